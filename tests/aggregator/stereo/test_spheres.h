#pragma once
// Spheres for the stereo tests: a triangulated sphere and calibrated views of a textured one
// (ray-traced per pixel, so masks and images are exact to the pixel).

#include <Eigen/Core>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator::testing {

// A sphere by subdividing an icosahedron `levels` times (SubdivideLongEdges on every edge),
// vertices on the sphere, oriented outwards.
TriangleMesh Icosphere(const Eigen::Vector3d& centre, double radius, int levels);

// `mesh` with `piece` appended as a separate piece (its vertices after the mesh's).
void AppendPiece(const TriangleMesh& piece, TriangleMesh* mesh);

// `cameras` views (width x height, focal length `focal` px, centred principal point) on a ring
// of radius `distance` around the z axis at the centre's height, looking at the sphere; every
// pixel whose ray meets the sphere is silhouette and shows a fixed texture of the surface
// point (sines of a few centimetres' wavelength), the rest a dark background.
std::vector<StereoView> TexturedSphereViews(const Eigen::Vector3d& centre, double radius,
                                            int cameras, double distance, int width, int height,
                                            double focal);

}  // namespace silnet::aggregator::testing

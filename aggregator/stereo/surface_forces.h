#pragma once
// The forces of the local surface refinement (thesis 7.4.3), each a displacement of a vertex
// along its normal:
//   texture     the offset along the normal where a patch tangent to the surface is most
//               photo-consistent (PatchScorer::Plane), searched at a few offsets and refined
//               by a parabola through the best and its neighbours;
//   silhouette  for a vertex that projects onto a view's background pixels, the offset that
//               brings it back to their centres; for one on a view's rim (its normal nearly
//               perpendicular to the viewing ray) inside the silhouette near the outline, the
//               offset that brings its projection onto the outline; both from the
//               signed distance map linearised at the vertex (as Hernandez and Schmitt's
//               silhouette force); the smallest over the views, so no view's outline is
//               crossed to reach another's.
// Normals are the area-weighted means of the faces around each vertex.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/patch_photo_consistency.h"
#include "aggregator/stereo/stereo_views.h"
#include "aggregator/stereo/taubin_smoothing.h"

namespace silnet::aggregator {

// Unit outward normals of the vertices (zero for a vertex in no triangle).
std::vector<Eigen::Vector3d> VertexNormals(const TriangleMesh& mesh);

// Mean curvature of the surface at every vertex (1/metres, positive where it is convex): the
// curvature of the sphere through the vertex, tangent to its normal, that best fits its
// neighbours (FindVertexNeighbours of the mesh), averaged over the 1-ring `rounds` times (a
// lattice's staircase makes single estimates noisy).
std::vector<double> VertexCurvatures(const TriangleMesh& mesh, const VertexNeighbours& neighbours,
                                     const std::vector<Eigen::Vector3d>& normals, int rounds);

// A displacement along the normal (metres) and how much it is trusted (0 = no force).
struct NormalOffset {
  float offset = 0;
  float weight = 0;
};

// Settings of the texture force.
struct TextureForceOptions {
  double range = 0;        // metres, > 0: offsets searched in [-range, range]
  double step = 0;         // metres, > 0: between searched offsets
  double patch_step = 0;   // metres, > 0: between the patch's points
  double min_score = 0.5;  // a best score below this gives no force
};

// The texture force of every vertex (weight = the best score), on `threads` threads; patches
// bent to the vertices' `curvatures` (VertexCurvatures), at most to a sphere as wide as the
// patch. Vertices with skip[i] != 0 (if `skip` is not empty) get no force.
std::vector<NormalOffset> TextureForces(const TriangleMesh& mesh,
                                        const std::vector<Eigen::Vector3d>& normals,
                                        const std::vector<double>& curvatures,
                                        const PatchScorer& scorer,
                                        const TextureForceOptions& options, int threads,
                                        const std::vector<uint8_t>& skip = {});

// Settings of the silhouette force.
struct SilhouetteForceOptions {
  double rim_cos = 0.05;         // a rim: |normal . viewing direction| below this
  double rim_distance_px = 3.0;  // and the projection within this of the outline
};

// The silhouette force from the views' masks (signed distance maps computed once; a view
// whose mask has no outline, all silhouette or all background, gives none).
class SilhouetteForce {
 public:
  SilhouetteForce(const std::vector<StereoView>& views, const SilhouetteForceOptions& options);

  // The force on a vertex at `x` with unit normal `normal` (weight 1, or 0 when no view
  // pushes or pulls it).
  NormalOffset At(const Eigen::Vector3d& x, const Eigen::Vector3d& normal) const;
  // At() for every vertex of `mesh` with its `normals` (none for a zero normal), on `threads`
  // threads.
  std::vector<NormalOffset> AtVertices(const TriangleMesh& mesh,
                                       const std::vector<Eigen::Vector3d>& normals,
                                       int threads) const;

 private:
  struct View {
    Eigen::Matrix<double, 3, 4> projection;
    Eigen::Vector3d centre;
    cv::Mat signed_distance;  // CV_32FC1, pixels, positive inside; empty: no outline
  };
  std::vector<View> views_;
  SilhouetteForceOptions options_;
};

}  // namespace silnet::aggregator

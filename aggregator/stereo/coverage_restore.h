#pragma once
// Keeps a deformed surface as silhouette-consistent as the surface it came from: wherever the
// deformation (surface_refinement.h) uncovered inner silhouette pixels that the original
// surface covered, the vertices that project near them go back to where they started, and
// that is repeated, over a wider neighbourhood each round, until no such pixel is left.
// Vertices that started on the original surface (the cut's own, and midpoints of its edges)
// put back together reproduce it, so enough rounds always restore the coverage.

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "aggregator/stereo/stereo_views.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The inner silhouette pixels (InnerSilhouettePixels) `surface` covers in each view: CV_8UC1,
// 255 there.
std::vector<cv::Mat> CoveredInnerPixels(const TriangleMesh& surface,
                                        const std::vector<StereoView>& views);

// True if `point` lies in front of the camera of `projection` and projects onto a non-zero
// pixel of `mask` (CV_8UC1; the pixel whose centre is nearest).
bool ProjectsOntoMarkedPixel(const cv::Mat& mask, const Matrix34d& projection,
                             const Eigen::Vector3f& point);

// What the restoration did.
struct CoverageRestoreStats {
  size_t rounds = 0;
  size_t restored = 0;         // vertices put back (counted once per round)
  size_t still_uncovered = 0;  // pixels of `covered` still missed after the last round
};

// Puts vertices of `mesh` back to `starts` (one per vertex, on the original surface) until
// every pixel of `covered` (CoveredInnerPixels of the original) is covered again, for at most
// `rounds` rounds: round r puts back every vertex that projects within 2 + 2r pixels of an
// uncovered one.
CoverageRestoreStats RestoreCoverage(const std::vector<StereoView>& views,
                                     const std::vector<cv::Mat>& covered,
                                     const std::vector<Eigen::Vector3f>& starts, int rounds,
                                     TriangleMesh* mesh);

}  // namespace silnet::aggregator

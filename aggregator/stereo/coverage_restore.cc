#include "aggregator/stereo/coverage_restore.h"

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/stereo/model_evaluation.h"
#include "shared/util/check.h"

namespace silnet::aggregator {

std::vector<cv::Mat> CoveredInnerPixels(const TriangleMesh& surface,
                                        const std::vector<StereoView>& views) {
  std::vector<cv::Mat> covered;
  covered.reserve(views.size());
  for (const StereoView& view : views)
    covered.push_back(InnerSilhouettePixels(view.mask) &
                      RenderMeshSilhouette(surface, view.camera));
  return covered;
}

bool ProjectsOntoMarkedPixel(const cv::Mat& mask, const Matrix34d& projection,
                             const Eigen::Vector3f& point) {
  const Eigen::Vector3d p = projection * point.cast<double>().homogeneous();
  if (p.z() <= 0) return false;
  const int x = static_cast<int>(std::lround(p.x() / p.z()));
  const int y = static_cast<int>(std::lround(p.y() / p.z()));
  return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uint8_t>(y, x) != 0;
}

CoverageRestoreStats RestoreCoverage(const std::vector<StereoView>& views,
                                     const std::vector<cv::Mat>& covered,
                                     const std::vector<Eigen::Vector3f>& starts, int rounds,
                                     TriangleMesh* mesh) {
  SILNET_CHECK(covered.size() == views.size());
  SILNET_CHECK(starts.size() == mesh->vertices.size());
  CoverageRestoreStats stats;
  for (int round = 0;; ++round) {
    // Each view's uncovered pixels, widened by the round's radius.
    std::vector<cv::Mat> near(views.size());
    size_t uncovered = 0;
    const int radius = 2 + 2 * round;
    const cv::Mat disc =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
    for (size_t v = 0; v < views.size(); ++v) {
      const cv::Mat missed = covered[v] & ~RenderMeshSilhouette(*mesh, views[v].camera);
      const int count = cv::countNonZero(missed);
      if (count == 0) continue;
      uncovered += static_cast<size_t>(count);
      cv::dilate(missed, near[v], disc);
    }
    stats.still_uncovered = uncovered;
    if (uncovered == 0 || round == rounds) break;
    ++stats.rounds;
    for (size_t v = 0; v < views.size(); ++v) {
      if (near[v].empty()) continue;
      const Matrix34d projection = views[v].camera.ProjectionMatrix();
      for (size_t i = 0; i < mesh->vertices.size(); ++i) {
        if (mesh->vertices[i] == starts[i]) continue;
        if (!ProjectsOntoMarkedPixel(near[v], projection, mesh->vertices[i])) continue;
        mesh->vertices[i] = starts[i];
        ++stats.restored;
      }
    }
  }
  return stats;
}

}  // namespace silnet::aggregator

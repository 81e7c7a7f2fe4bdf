#include "aggregator/stereo/tet_silhouette_step.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/stereo/lattice_ray.h"
#include "aggregator/stereo/model_evaluation.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// The cell at the middle of the ray's first stretch of cells not labelled exterior, or -1.
int32_t MiddleOfFirstStretch(const TetPointLocator& locator, const std::vector<CellLabel>& labels,
                             const Eigen::Vector3d& centre, const Eigen::Vector3d& direction,
                             double near, double far, double step) {
  double first = -1, last = -1;
  for (double s = near; s <= far; s += step) {
    const int32_t t = locator.Locate(centre + s * direction);
    const bool inside = t >= 0 && labels[static_cast<size_t>(t)] != CellLabel::kExterior;
    if (inside) {
      if (first < 0) first = s;
      last = s;
    } else if (first >= 0) {
      break;
    }
  }
  if (first < 0) return -1;
  return locator.Locate(centre + 0.5 * (first + last) * direction);
}

}  // namespace

TetSilhouetteStats EnforceSilhouettesOnTets(TetGraphCut* cut, const TetMesh& mesh,
                                            const std::vector<CellLabel>& labels,
                                            const TetPointLocator& locator,
                                            const std::vector<StereoView>& views,
                                            const TetSilhouetteOptions& options) {
  SILNET_CHECK(options.ray_step > 0 && options.pixel_stride >= 1);
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices)
    box.extend(v);
  std::vector<cv::Mat> inner;
  for (const StereoView& view : views)
    inner.push_back(InnerSilhouettePixels(view.mask, options.margin_px));
  TetSilhouetteStats stats;
  for (int round = 0; round <= options.rounds; ++round) {
    const TriangleMesh surface = cut->Surface();
    size_t missed = 0;
    std::vector<int32_t> force;
    for (size_t v = 0; v < views.size(); ++v) {
      const CameraModel& camera = views[v].camera;
      const cv::Mat covered = RenderMeshSilhouette(surface, camera);
      const Eigen::Vector3d centre = camera.Center();
      for (int y = 0; y < inner[v].rows; ++y) {
        for (int x = 0; x < inner[v].cols; ++x) {
          if (inner[v].at<uint8_t>(y, x) == 0 || covered.at<uint8_t>(y, x) != 0) continue;
          ++missed;
          if (round == options.rounds) continue;
          // The first round, where most pixels are missed, takes every stride-th; later ones
          // every pixel still missed.
          const int stride = round == 0 ? options.pixel_stride : 1;
          if (y % stride != 0 || x % stride != 0) continue;
          const Eigen::Vector3d direction =
              (camera.R.transpose() * camera.PixelRay(Eigen::Vector2d(x, y))).normalized();
          const auto range = ClipRay(box, centre, direction);
          if (!range) continue;
          const int32_t cell = MiddleOfFirstStretch(locator, labels, centre, direction,
                                                    range->first, range->second, options.ray_step);
          if (cell >= 0) force.push_back(cell);
        }
      }
    }
    stats.missed.push_back(missed);
    if (round == options.rounds || missed == 0) break;
    std::sort(force.begin(), force.end());
    force.erase(std::unique(force.begin(), force.end()), force.end());
    const size_t added = cut->ForceInterior(force);
    stats.forced += added;
    if (added == 0) break;
  }
  return stats;
}

}  // namespace silnet::aggregator

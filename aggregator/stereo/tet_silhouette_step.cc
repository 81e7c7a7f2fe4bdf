#include "aggregator/stereo/tet_silhouette_step.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/stereo/lattice_ray.h"
#include "aggregator/stereo/model_evaluation.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// The cell at the middle of the ray's first stretch of cells neither labelled nor forced
// exterior, or -1.
int32_t MiddleOfFirstStretch(const TetPointLocator& locator, const std::vector<CellLabel>& labels,
                             const std::vector<uint8_t>& forced_side, const Eigen::Vector3d& centre,
                             const Eigen::Vector3d& direction, double near, double far,
                             double step) {
  double first = -1, last = -1;
  for (double s = near; s <= far; s += step) {
    const int32_t t = locator.Locate(centre + s * direction);
    const bool inside = t >= 0 && labels[static_cast<size_t>(t)] != CellLabel::kExterior &&
                        forced_side[static_cast<size_t>(t)] != 2;
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

// Appends the interior cells along the ray that were not forced interior.
void InteriorCellsOnRay(const TetPointLocator& locator, const std::vector<uint8_t>& interior,
                        const std::vector<uint8_t>& forced_side, const Eigen::Vector3d& centre,
                        const Eigen::Vector3d& direction, double near, double far, double step,
                        std::vector<int32_t>* cells) {
  int32_t last = -1;
  for (double s = near; s <= far; s += step) {
    const int32_t t = locator.Locate(centre + s * direction);
    if (t < 0 || t == last) continue;
    last = t;
    if (interior[static_cast<size_t>(t)] && forced_side[static_cast<size_t>(t)] == 0)
      cells->push_back(t);
  }
}

// Sorted, without repeats.
void SortUnique(std::vector<int32_t>* cells) {
  std::sort(cells->begin(), cells->end());
  cells->erase(std::unique(cells->begin(), cells->end()), cells->end());
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
  std::vector<cv::Mat> inner, outer;
  for (const StereoView& view : views) {
    inner.push_back(InnerSilhouettePixels(view.mask, options.margin_px));
    outer.push_back(InnerSilhouettePixels(view.mask == 0, options.margin_px));
  }
  TetSilhouetteStats stats;
  for (int round = 0; round <= options.rounds; ++round) {
    const TriangleMesh surface = cut->Surface();
    const std::vector<uint8_t>& interior = cut->Interior();
    const std::vector<uint8_t>& forced_side = cut->ForcedSide();
    size_t missed = 0, covered_outer = 0;
    std::vector<int32_t> force_in, force_out;
    for (size_t v = 0; v < views.size(); ++v) {
      const CameraModel& camera = views[v].camera;
      const cv::Mat covered = RenderMeshSilhouette(surface, camera);
      const Eigen::Vector3d centre = camera.Center();
      // The first round, where most pixels are missed, takes every stride-th; later ones
      // every pixel still wrong.
      const int stride = round == 0 ? options.pixel_stride : 1;
      for (int y = 0; y < inner[v].rows; ++y) {
        for (int x = 0; x < inner[v].cols; ++x) {
          const bool is_missed = inner[v].at<uint8_t>(y, x) != 0 && covered.at<uint8_t>(y, x) == 0;
          const bool is_covered = outer[v].at<uint8_t>(y, x) != 0 && covered.at<uint8_t>(y, x) != 0;
          if (!is_missed && !is_covered) continue;
          (is_missed ? missed : covered_outer) += 1;
          if (round == options.rounds || y % stride != 0 || x % stride != 0) continue;
          const Eigen::Vector3d direction =
              (camera.R.transpose() * camera.PixelRay(Eigen::Vector2d(x, y))).normalized();
          const auto range = ClipRay(box, centre, direction);
          if (!range) continue;
          if (is_covered) {
            // The ray must not meet the object: every cell on it is exterior (thesis 7.4.2).
            // Sampled finer, and finer each round, as a ray near the outline may cross a cell
            // for a short stretch only.
            const double step = options.ray_step / (4 << std::min(round, 4));
            InteriorCellsOnRay(locator, interior, forced_side, centre, direction, range->first,
                               range->second, step, &force_out);
            continue;
          }
          const int32_t cell = MiddleOfFirstStretch(locator, labels, forced_side, centre, direction,
                                                    range->first, range->second, options.ray_step);
          if (cell >= 0) force_in.push_back(cell);
        }
      }
    }
    stats.missed.push_back(missed);
    stats.covered.push_back(covered_outer);
    if (round == options.rounds || (missed == 0 && covered_outer == 0)) break;
    SortUnique(&force_out);
    SortUnique(&force_in);
    const size_t removed = cut->ForceExterior(force_out);
    const size_t added = cut->ForceInterior(force_in);
    stats.forced += added;
    stats.forced_out += removed;
    if (added == 0 && removed == 0) break;
  }
  return stats;
}

}  // namespace silnet::aggregator

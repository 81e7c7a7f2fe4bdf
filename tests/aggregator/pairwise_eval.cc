#include "tests/aggregator/pairwise_eval.h"

#include <algorithm>

#include "aggregator/pairwise/epipolar_model.h"
#include "shared/geometry/epipolar.h"
#include "shared/silhouette/hull_tangents.h"

namespace silnet::aggregator::testing {

double MedianEpipolarDistance(const SimCapture& capture, size_t i, size_t j,
                              const Eigen::Matrix3d& f, int frames, std::mt19937_64& rng) {
  const CameraModel& ci = capture.cameras[i];
  const CameraModel& cj = capture.cameras[j];
  std::uniform_real_distribution<double> when(0.0, frames / ci.fps);
  std::vector<double> distances;
  for (int t = 0; t < 40; ++t) {
    for (const auto& primitive : capture.scene->PrimitivesAt(ci.ExposureTime(0) + when(rng))) {
      for (const Eigen::Vector3d& x : primitive.SampleSurface(4, rng)) {
        const auto pi = ci.Project(x), pj = cj.Project(x);
        if (!pi || !pj || !ci.InImage(*pi) || !cj.InImage(*pj)) continue;
        distances.push_back(
            SymmetricEpipolarDistance(f, ci.UndistortPixel(*pi), cj.UndistortPixel(*pj)));
      }
    }
  }
  if (distances.empty()) return 1e9;
  std::nth_element(distances.begin(),
                   distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2),
                   distances.end());
  return distances[distances.size() / 2];
}

double TrueEpipoleInsideFraction(const SimCapture& capture, size_t i, size_t j) {
  const Eigen::Matrix3d f = FundamentalFromCameras(capture.cameras[i], capture.cameras[j]);
  const Eigen::Vector3d e_i = EpipoleInFirstView(f), e_j = EpipoleInSecondView(f);
  const double offset = capture.cameras[i].time_offset - capture.cameras[j].time_offset;
  size_t frames = 0, inside = 0;
  for (const SilhouetteFrame& fi : capture.sequences[i].frames) {
    if (capture.sequences[i].Usable(fi.index) == nullptr) continue;
    const SilhouetteFrame* fj = capture.sequences[j].Usable(
        static_cast<uint64_t>(std::max(0.0, std::round(static_cast<double>(fi.index) + offset))));
    if (fj == nullptr) continue;
    ++frames;
    if (!TangentsFromPoint(fi.hull, e_i) || !TangentsFromPoint(fj->hull, e_j)) ++inside;
  }
  return frames == 0 ? 1.0 : static_cast<double>(inside) / static_cast<double>(frames);
}

PairEvaluation Evaluate(const SimCapture& capture, size_t i, size_t j, const PairwiseResult& result,
                        int frames) {
  PairEvaluation e;
  std::mt19937_64 rng(17 + 31 * i + j);
  e.median_epipolar_px = MedianEpipolarDistance(capture, i, j, result.F, frames, rng);
  e.true_offset = capture.cameras[i].time_offset - capture.cameras[j].time_offset;
  e.offset_error = std::abs(result.offset - e.true_offset);
  e.true_epipole_inside = TrueEpipoleInsideFraction(capture, i, j);
  return e;
}

}  // namespace silnet::aggregator::testing

#include "aggregator/calibration/pair_checks.h"

#include <fmt/format.h>

#include <algorithm>

#include "aggregator/pairwise/fundamental_distance.h"
#include "shared/geometry/epipolar.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {
namespace {

// How far the pairwise estimate is from the derived geometry where it was measured: the
// median symmetric epipolar distance of its inlier correspondences (at its offset, lens
// distortion removed) under the derived F. Without correspondences, Zhang's distance of the
// two F over the image.
double EstimateDisagreement(const PairwiseResult& r, const CameraModel& ci, const CameraModel& cj,
                            const Eigen::Matrix3d& derived) {
  if (r.inlier_matches.empty()) return FundamentalDistance(r.F, derived, ci.width, ci.height);
  std::vector<double> distances;
  distances.reserve(r.inlier_matches.size());
  for (const TimedMatch& m : r.inlier_matches) {
    distances.push_back(SymmetricEpipolarDistance(derived, ci.UndistortPixel(m.x_i),
                                                  cj.UndistortPixel(m.XjAt(r.offset))));
  }
  return UpperMedian(std::move(distances));
}

}  // namespace

std::vector<PairCheck> CheckPairs(const std::vector<CameraModel>& cameras,
                                  const std::vector<CameraPlacement>& placement,
                                  const std::vector<PairwiseResult>& pairs,
                                  const std::vector<bool>& used, double corrected_px) {
  const auto index_of = [&](const std::string& id) {
    return static_cast<size_t>(
        std::find_if(cameras.begin(), cameras.end(), [&](const auto& c) { return c.id == id; }) -
        cameras.begin());
  };
  std::vector<PairCheck> checks;
  for (size_t p = 0; p < pairs.size(); ++p) {
    const PairwiseResult& r = pairs[p];
    PairCheck check;
    check.i = index_of(r.camera_i);
    check.j = index_of(r.camera_j);
    if (check.i >= cameras.size() || check.j >= cameras.size()) continue;
    check.pairwise_status = r.status;
    check.pairwise_reason = r.reason;
    check.used = p < used.size() && used[p];
    if (!placement[check.i].placed || !placement[check.j].placed) {
      check.note = fmt::format("not checked: {} is not calibrated",
                               placement[check.i].placed ? r.camera_j : r.camera_i);
      checks.push_back(std::move(check));
      continue;
    }
    const CameraModel& ci = cameras[check.i];
    const CameraModel& cj = cameras[check.j];
    check.F_derived = FundamentalFromCameras(ci, cj);
    if (r.status == PairStatus::kOk) {
      check.distance_px = EstimateDisagreement(r, ci, cj, check.F_derived);
      check.corrected = check.distance_px > corrected_px;
      check.note =
          check.corrected
              ? fmt::format("the estimate was {:.1f} px off; the calibration's replaces it",
                            check.distance_px)
              : fmt::format("agrees with the calibration ({:.2f} px)", check.distance_px);
    } else {
      check.corrected = true;
      check.note = "no trusted estimate; the calibration supplies this pair's geometry";
    }
    checks.push_back(std::move(check));
  }
  return checks;
}

}  // namespace silnet::aggregator

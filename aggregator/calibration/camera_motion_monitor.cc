#include "aggregator/calibration/camera_motion_monitor.h"

#include <fmt/format.h>

#include "shared/util/check.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {

std::string CameraMotionOptions::Validate() const {
  if (!(jump_factor >= 1.0)) return "the jump factor must be at least 1";
  if (!(min_jump_px >= 0.0)) return "the minimum jump must not be negative";
  if (min_matches < 1) return "at least one match per pair is needed";
  if (!(own_pairs_jumped > 0.0 && own_pairs_jumped <= 1.0) ||
      !(other_pairs_jumped >= 0.0 && other_pairs_jumped < 1.0))
    return "the shares of jumped pairs must lie in (0, 1]";
  if (confirmations < 1) return "at least one confirmation is needed";
  return "";
}

CameraMotionMonitor::CameraMotionMonitor(std::vector<CameraModel> cameras, std::vector<bool> placed,
                                         const CameraMotionOptions& options)
    : cameras_(std::move(cameras)),
      placed_(std::move(placed)),
      options_(options),
      suspect_runs_(cameras_.size(), 0) {
  SILNET_CHECK(placed_.size() == cameras_.size());
  const std::string invalid = options_.Validate();
  if (!invalid.empty()) throw InputError("camera motion monitor: " + invalid);
}

void CameraMotionMonitor::SetBaseline(const std::vector<SilhouetteSequence>& sequences) {
  baseline_ = MeasureEpipolarResiduals(cameras_, placed_, sequences, options_.min_matches);
  std::fill(suspect_runs_.begin(), suspect_runs_.end(), 0);
}

double CameraMotionMonitor::Baseline(size_t i, size_t j) const {
  for (const PairResidual& r : baseline_) {
    if (r.i == i && r.j == j) return r.median_px;
  }
  return -1.0;
}

std::vector<CameraMotionVerdict> CameraMotionMonitor::Check(
    const std::vector<SilhouetteSequence>& sequences) {
  const std::vector<PairResidual> now =
      MeasureEpipolarResiduals(cameras_, placed_, sequences, options_.min_matches);
  struct Judged {
    size_t i, j;
    double now, baseline;
    bool jumped;
  };
  std::vector<Judged> judged;
  for (const PairResidual& r : now) {
    const double base = Baseline(r.i, r.j);
    if (!r.measured() || base < 0.0) continue;
    const bool jumped =
        r.median_px > options_.jump_factor * base && r.median_px > base + options_.min_jump_px;
    judged.push_back({r.i, r.j, r.median_px, base, jumped});
  }
  std::vector<CameraMotionVerdict> verdicts;
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (!placed_[c]) continue;
    CameraMotionVerdict v;
    v.camera = c;
    v.camera_id = cameras_[c].id;
    std::vector<double> residuals, baselines;
    size_t others = 0, others_jumped = 0;
    for (const Judged& p : judged) {
      if (p.i == c || p.j == c) {
        ++v.pairs_measured;
        v.pairs_jumped += p.jumped ? 1 : 0;
        residuals.push_back(p.now);
        baselines.push_back(p.baseline);
      } else {
        ++others;
        others_jumped += p.jumped ? 1 : 0;
      }
    }
    if (!residuals.empty()) {
      v.residual_px = UpperMedian(std::move(residuals));
      v.baseline_px = UpperMedian(std::move(baselines));
    }
    const double own_share = v.pairs_measured == 0 ? 0.0
                                                   : static_cast<double>(v.pairs_jumped) /
                                                         static_cast<double>(v.pairs_measured);
    const double other_share =
        others == 0 ? 0.0 : static_cast<double>(others_jumped) / static_cast<double>(others);
    v.suspect = v.pairs_jumped >= 2 && own_share >= options_.own_pairs_jumped &&
                other_share <= options_.other_pairs_jumped;
    suspect_runs_[c] = v.suspect ? suspect_runs_[c] + 1 : 0;
    v.moved = suspect_runs_[c] >= options_.confirmations;
    verdicts.push_back(std::move(v));
  }
  return verdicts;
}

void CameraMotionMonitor::ReplaceCamera(size_t camera, const CameraModel& model,
                                        const std::vector<SilhouetteSequence>& sequences) {
  SILNET_CHECK(camera < cameras_.size());
  cameras_[camera] = model;
  placed_[camera] = true;
  suspect_runs_[camera] = 0;
  const std::vector<PairResidual> fresh =
      MeasureEpipolarResiduals(cameras_, placed_, sequences, options_.min_matches);
  std::erase_if(baseline_, [&](const PairResidual& r) { return r.i == camera || r.j == camera; });
  for (const PairResidual& r : fresh) {
    if (r.i == camera || r.j == camera) baseline_.push_back(r);
  }
}

}  // namespace silnet::aggregator

#include "aggregator/calibration/focal_search.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

namespace silnet::aggregator {
namespace {

// The templates with square pixels, the principal point at the centre and focal length
// factor * larger side.
std::vector<CameraModel> WithFocal(const std::vector<CameraModel>& templates, double factor) {
  std::vector<CameraModel> cameras = templates;
  for (CameraModel& c : cameras) {
    const double f = factor * std::max(c.width, c.height);
    c.K << f, 0.0, 0.5 * (c.width - 1), 0.0, f, 0.5 * (c.height - 1), 0.0, 0.0, 1.0;
    c.dist.setZero();
  }
  return cameras;
}

// How well a start agrees: pairs used, then the mean of their rotation errors.
struct StartScore {
  size_t agreeing = 0;
  double mean_error_deg = 0.0;
  bool BetterThan(const StartScore& other) const {
    if (agreeing != other.agreeing) return agreeing > other.agreeing;
    return mean_error_deg < other.mean_error_deg;
  }
};

StartScore Score(const GlobalStart& start) {
  StartScore score;
  if (!start.ok) return score;
  double sum = 0.0;
  for (double e : start.rotation_error_deg) {
    if (e < 0.0) continue;
    ++score.agreeing;
    sum += e;
  }
  score.mean_error_deg = score.agreeing > 0 ? sum / static_cast<double>(score.agreeing) : 0.0;
  return score;
}

// The search over the focal lengths at one rotation tolerance (`start_options`').
FocalSearchResult SearchAtTolerance(const std::vector<CameraModel>& templates,
                                    const std::vector<PairwiseResult>& pairs,
                                    const FocalSearchOptions& options,
                                    const GlobalStartOptions& start_options) {
  FocalSearchResult best;
  StartScore best_score;
  const int steps = std::max(options.steps, 2);
  for (int s = 0; s < steps; ++s) {
    const double factor = options.min_factor * std::pow(options.max_factor / options.min_factor,
                                                        static_cast<double>(s) / (steps - 1));
    std::vector<CameraModel> cameras = WithFocal(templates, factor);
    GlobalStart start = EstimateGlobalStart(cameras, pairs, start_options);
    const StartScore score = Score(start);
    spdlog::debug("focal search: {:.3f} x side: {} pairs agree, {:.2f} deg{}{}", factor,
                  score.agreeing, score.mean_error_deg, start.ok ? "" : "; ", start.reason);
    if (start.ok && (!best.ok || score.BetterThan(best_score))) {
      best.ok = true;
      best.factor = factor;
      best.cameras = std::move(cameras);
      best.start = std::move(start);
      best_score = score;
    }
  }
  best.detail = best.ok ? fmt::format(
                              "focal length {:.3f} x the larger image side: {} pairs agree "
                              "to {:.2f} deg on average",
                              best.factor, best_score.agreeing, best_score.mean_error_deg)
                        : fmt::format(
                              "no focal length in the range gives three cameras whose "
                              "pairs agree within {:.1f} deg",
                              start_options.rotation_tolerance_deg);
  return best;
}

}  // namespace

FocalSearchResult SearchCommonFocal(const std::vector<CameraModel>& templates,
                                    const std::vector<PairwiseResult>& pairs,
                                    const FocalSearchOptions& options,
                                    const GlobalStartOptions& start_options) {
  FocalSearchResult result = SearchAtTolerance(templates, pairs, options, start_options);
  if (result.ok || !(options.fallback_tolerance_factor > 1.0)) return result;
  GlobalStartOptions looser = start_options;
  looser.rotation_tolerance_deg *= options.fallback_tolerance_factor;
  spdlog::info("focal length search: {}; searching again within {:.1f} deg", result.detail,
               looser.rotation_tolerance_deg);
  FocalSearchResult second = SearchAtTolerance(templates, pairs, options, looser);
  if (second.ok) {
    second.detail =
        fmt::format("{} (within {:.1f} deg: none agreed within {:.1f})", second.detail,
                    looser.rotation_tolerance_deg, start_options.rotation_tolerance_deg);
  }
  return second;
}

}  // namespace silnet::aggregator

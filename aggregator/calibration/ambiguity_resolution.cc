#include "aggregator/calibration/ambiguity_resolution.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>

#include "aggregator/calibration/triplet_consistency.h"
#include "aggregator/calibration/view_graph.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {
namespace {

// Trusted fundamental matrices by camera index: F(a, b) maps points of a to lines of b.
class TrustedPairs {
 public:
  TrustedPairs(const std::vector<CameraModel>& cameras, const std::vector<PairwiseResult>& pairs)
      : cameras_(cameras) {
    for (size_t p = 0; p < pairs.size(); ++p) {
      const size_t i = Index(pairs[p].camera_i), j = Index(pairs[p].camera_j);
      if (i < cameras.size() && j < cameras.size() && pairs[p].status == PairStatus::kOk)
        f_[{i, j}] = pairs[p].F;
    }
  }
  size_t Index(const std::string& id) const { return CameraIndex(cameras_, id); }
  bool Has(size_t a, size_t b) const { return f_.count({a, b}) > 0 || f_.count({b, a}) > 0; }
  Eigen::Matrix3d F(size_t a, size_t b) const {
    const auto it = f_.find({a, b});
    return it != f_.end() ? it->second : f_.at({b, a}).transpose();
  }
  void Trust(size_t a, size_t b, const Eigen::Matrix3d& F) { f_[{a, b}] = F; }
  ViewSize Size(size_t c) const { return {cameras_[c].width, cameras_[c].height}; }

 private:
  const std::vector<CameraModel>& cameras_;
  std::map<std::pair<size_t, size_t>, Eigen::Matrix3d> f_;
};

// Median triplet residual of F_ij against every camera k trusted with both i and j; the
// third cameras' ids go to `thirds`. -1 without such a camera.
double MedianResidual(const TrustedPairs& trusted, size_t i, size_t j, const Eigen::Matrix3d& F_ij,
                      size_t cameras, std::vector<std::string>* thirds,
                      const std::vector<CameraModel>& models) {
  std::vector<double> residuals;
  thirds->clear();
  for (size_t k = 0; k < cameras; ++k) {
    if (k == i || k == j || !trusted.Has(i, k) || !trusted.Has(j, k)) continue;
    residuals.push_back(TripletInconsistency(F_ij, trusted.F(i, k), trusted.F(j, k),
                                             trusted.Size(i), trusted.Size(j), trusted.Size(k)));
    thirds->push_back(models[k].id);
  }
  return residuals.empty() ? -1.0 : UpperMedian(residuals);
}

}  // namespace

std::vector<AmbiguityDecision> ResolveAmbiguousPairs(const std::vector<CameraModel>& cameras,
                                                     std::vector<PairwiseResult>* pairs,
                                                     const AmbiguityOptions& options) {
  TrustedPairs trusted(cameras, *pairs);
  std::vector<AmbiguityDecision> decisions;
  for (size_t p = 0; p < pairs->size(); ++p) {
    if ((*pairs)[p].status != PairStatus::kAmbiguous) continue;
    decisions.push_back({p, false, {}, "no third camera trusted with both"});
  }
  // Resolving one pair can make a triplet for another: repeat until nothing changes.
  for (bool changed = true; changed;) {
    changed = false;
    for (AmbiguityDecision& d : decisions) {
      if (d.resolved) continue;
      PairwiseResult& pair = (*pairs)[d.pair];
      const size_t i = trusted.Index(pair.camera_i), j = trusted.Index(pair.camera_j);
      if (i >= cameras.size() || j >= cameras.size()) continue;
      std::vector<Eigen::Matrix3d> candidates = {pair.F};
      for (const PairCandidate& a : pair.alternatives)
        candidates.push_back(a.F);
      std::vector<std::string> thirds;
      d.residual_px.clear();
      for (const Eigen::Matrix3d& F : candidates)
        d.residual_px.push_back(MedianResidual(trusted, i, j, F, cameras.size(), &thirds, cameras));
      if (thirds.empty()) continue;
      const size_t best = static_cast<size_t>(
          std::min_element(d.residual_px.begin(), d.residual_px.end()) - d.residual_px.begin());
      double next = -1.0;
      for (size_t c = 0; c < candidates.size(); ++c) {
        if (c != best && (next < 0.0 || d.residual_px[c] < next)) next = d.residual_px[c];
      }
      const std::string with = fmt::format("{}", fmt::join(thirds, ", "));
      if (d.residual_px[best] > options.max_inconsistency_px) {
        d.note =
            fmt::format("no candidate agrees with {} (best {:.1f} px)", with, d.residual_px[best]);
        continue;
      }
      if (next >= 0.0 && next < options.min_ratio * d.residual_px[best]) {
        d.note = fmt::format("{} cannot tell candidates apart ({:.1f} vs {:.1f} px)", with,
                             d.residual_px[best], next);
        continue;
      }
      const std::string why =
          next >= 0.0
              ? fmt::format("resolved by {}: candidate {} of {} agrees to {:.2f} px (next {:.1f})",
                            with, best + 1, candidates.size(), d.residual_px[best], next)
              : fmt::format("confirmed by {}: agrees to {:.2f} px", with, d.residual_px[best]);
      if (best == 0) {
        pair.status = PairStatus::kOk;
        pair.reason = why;
      } else {
        pair.Choose(best - 1, why);
      }
      d.resolved = true;
      d.note = why;
      trusted.Trust(i, j, pair.F);
      spdlog::info("pair {}-{}: {}", pair.camera_i, pair.camera_j, why);
      changed = true;
    }
  }
  for (const AmbiguityDecision& d : decisions) {
    if (!d.resolved) {
      const PairwiseResult& pair = (*pairs)[d.pair];
      spdlog::info("pair {}-{} stays ambiguous: {}", pair.camera_i, pair.camera_j, d.note);
    }
  }
  return decisions;
}

}  // namespace silnet::aggregator

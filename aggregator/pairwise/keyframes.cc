#include "aggregator/pairwise/keyframes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "shared/silhouette/hull_tangents.h"

namespace silnet::aggregator {

Keyframes SelectKeyframes(const SilhouetteSequence& sequence, double fraction, size_t minimum) {
  // Extremal points for tangent directions 0, 45, 90, 135 degrees and their opposites.
  struct Motion {
    uint64_t index;
    double amount;
  };
  std::vector<Motion> motion;
  std::vector<Eigen::Vector2d> previous;
  uint64_t previous_index = 0;
  for (const SilhouetteFrame& frame : sequence.frames) {
    if (sequence.Usable(frame.index) == nullptr) continue;
    std::vector<Eigen::Vector2d> extremes;
    for (int d = 0; d < 8; ++d) {
      extremes.push_back(
          frame.hull.vertex(SupportingVertex(frame.hull, d * std::numbers::pi / 4.0)));
    }
    if (!previous.empty() && frame.index == previous_index + 1) {
      double amount = 0.0;
      for (size_t d = 0; d < extremes.size(); ++d)
        amount += (extremes[d] - previous[d]).norm();
      motion.push_back({frame.index, amount});
    }
    previous = std::move(extremes);
    previous_index = frame.index;
  }
  Keyframes keyframes;
  if (motion.empty()) return keyframes;
  const size_t count = std::min(
      motion.size(),
      std::max(minimum, static_cast<size_t>(fraction * static_cast<double>(motion.size()))));
  std::sort(motion.begin(), motion.end(),
            [](const Motion& a, const Motion& b) { return a.amount < b.amount; });
  for (size_t k = 0; k < count; ++k) {
    keyframes.slow.push_back(motion[k].index);
    keyframes.fast.push_back(motion[motion.size() - 1 - k].index);
  }
  std::sort(keyframes.slow.begin(), keyframes.slow.end());
  std::sort(keyframes.fast.begin(), keyframes.fast.end());
  return keyframes;
}

}  // namespace silnet::aggregator

#include "aggregator/calibration/addition_order.h"

#include <fmt/format.h>

#include <algorithm>

namespace silnet::aggregator {

std::optional<Addition> NextAddition(const ViewGraph& graph, const std::vector<bool>& placed,
                                     const std::vector<bool>& given_up,
                                     const AdditionCheck& acceptable) {
  std::optional<Addition> best;
  for (size_t k = 0; k < graph.cameras(); ++k) {
    if (placed[k] || given_up[k]) continue;
    std::vector<size_t> linked;
    for (size_t p : graph.Neighbours(k)) {
      if (placed[p]) linked.push_back(p);
    }
    std::sort(linked.begin(), linked.end(),
              [&](size_t a, size_t b) { return graph.Spread(k, a) > graph.Spread(k, b); });
    for (size_t x = 0; x < linked.size(); ++x) {
      for (size_t y = x + 1; y < linked.size(); ++y) {
        const size_t p = linked[x], q = linked[y];
        const double score = graph.Spread(k, q);
        if (best && score <= best->score) continue;
        if (!acceptable(k, p, q)) continue;
        best = Addition{k, p, q, score};
      }
    }
  }
  return best;
}

std::string ReasonNotPlaced(const ViewGraph& graph, const std::vector<bool>& placed, size_t k) {
  const std::vector<size_t> neighbours = graph.Neighbours(k);
  const size_t links = static_cast<size_t>(
      std::count_if(neighbours.begin(), neighbours.end(), [&](size_t p) { return placed[p]; }));
  if (neighbours.empty()) return "no trusted epipolar geometry links it to any other camera";
  if (links < 2) {
    return fmt::format(
        "only {} trusted link{} to the calibrated cameras ({} in all); adding a camera needs two",
        links, links == 1 ? "" : "s", neighbours.size());
  }
  return fmt::format(
      "its {} links to the calibrated cameras are degenerate (camera centres nearly collinear)",
      links);
}

}  // namespace silnet::aggregator

#include "aggregator/calibration/two_view_tracks.h"

#include <algorithm>

namespace silnet::aggregator {

std::vector<TwoViewTrack> CollectTracks(const ViewGraph& graph, const std::vector<bool>& selected,
                                        size_t max_per_link) {
  std::vector<TwoViewTrack> tracks;
  for (const ViewLink& link : graph.links()) {
    if (!selected[link.i] || !selected[link.j] || link.matches.empty()) continue;
    std::vector<const Correspondence*> sorted;
    sorted.reserve(link.matches.size());
    for (const Correspondence& c : link.matches)
      sorted.push_back(&c);
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const auto* a, const auto* b) { return a->frame_i < b->frame_i; });
    const size_t n = sorted.size();
    const size_t take = max_per_link == 0 ? n : std::min(n, max_per_link);
    for (size_t k = 0; k < take; ++k) {
      const Correspondence& c = *sorted[k * n / take];
      tracks.push_back({link.i, link.j, c.x_i, c.x_j, c.frame_i});
    }
  }
  return tracks;
}

}  // namespace silnet::aggregator

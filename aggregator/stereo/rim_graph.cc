#include "aggregator/stereo/rim_graph.h"

#include <algorithm>
#include <iterator>
#include <limits>
#include <unordered_map>

namespace silnet::aggregator {
namespace {

// The segments of one ray, in the loop's order of rays.
struct LoopRay {
  int position = 0;  // index of the ray's face along the loop
  std::vector<int> segments;
};

// The face pieces two segments both border.
std::vector<int> SharedPieces(const ViewEdgeSegment& a, const ViewEdgeSegment& b) {
  std::vector<int> shared;
  std::set_intersection(a.pieces.begin(), a.pieces.end(), b.pieces.begin(), b.pieces.end(),
                        std::back_inserter(shared));
  return shared;
}

// True if two segments border a common face piece.
bool SharePiece(const ViewEdgeSegment& a, const ViewEdgeSegment& b) {
  return !SharedPieces(a, b).empty();
}

// The shortest cycle through `rays` (at least two), one segment per ray; appends the chosen
// segments to `chosen` in loop order.
void ShortestCycle(const std::vector<LoopRay>& rays, int loop_length, const HullViewEdges& edges,
                   const std::vector<double>& weight, double discontinuity,
                   std::vector<int>& chosen) {
  const auto cost = [&](const LoopRay& from, int a, const LoopRay& to, int b) {
    const int step = (to.position - from.position + loop_length) % loop_length;
    const auto& sa = edges.segments[static_cast<size_t>(a)];
    const auto& sb = edges.segments[static_cast<size_t>(b)];
    return step == 1 && SharePiece(sa, sb)
               ? weight[static_cast<size_t>(a)] + weight[static_cast<size_t>(b)]
               : discontinuity;
  };
  const size_t m = rays.size();
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> best_path;
  for (const int start : rays[0].segments) {
    // dist[k][j]: the cheapest path from `start` to segment j of ray k; from[k][j] its previous.
    std::vector<std::vector<double>> dist(m);
    std::vector<std::vector<int>> from(m);
    dist[0].assign(1, 0.0);
    from[0].assign(1, -1);
    for (size_t k = 1; k < m; ++k) {
      const LoopRay& prev = rays[k - 1];
      const std::vector<int> prev_segments = k == 1 ? std::vector<int>{start} : prev.segments;
      dist[k].assign(rays[k].segments.size(), std::numeric_limits<double>::infinity());
      from[k].assign(rays[k].segments.size(), -1);
      for (size_t j = 0; j < rays[k].segments.size(); ++j) {
        for (size_t i = 0; i < prev_segments.size(); ++i) {
          const double d =
              dist[k - 1][i] + cost(prev, prev_segments[i], rays[k], rays[k].segments[j]);
          if (d < dist[k][j]) {
            dist[k][j] = d;
            from[k][j] = static_cast<int>(i);
          }
        }
      }
    }
    for (size_t j = 0; j < rays[m - 1].segments.size(); ++j) {
      const double d = dist[m - 1][j] + cost(rays[m - 1], rays[m - 1].segments[j], rays[0], start);
      if (d >= best) continue;
      best = d;
      best_path.assign(m, start);
      int at = static_cast<int>(j);
      for (size_t k = m - 1; k >= 1; --k) {
        best_path[k] = rays[k].segments[static_cast<size_t>(at)];
        at = from[k][static_cast<size_t>(at)];
      }
    }
  }
  chosen.insert(chosen.end(), best_path.begin(), best_path.end());
}

}  // namespace

TrueSegments ChooseTrueSegments(const HullViewEdges& edges, const std::vector<ConePlane>& planes,
                                const std::vector<double>& segment_weight,
                                double discontinuity_cost) {
  TrueSegments result;
  result.is_true.assign(edges.segments.size(), false);
  std::unordered_map<int, std::vector<int>> segments_of_ray;
  for (size_t s = 0; s < edges.segments.size(); ++s)
    segments_of_ray[edges.segments[s].ray].push_back(static_cast<int>(s));
  std::vector<bool> visited(planes.size(), false);
  for (size_t first = 0; first < planes.size(); ++first) {
    if (visited[first]) continue;
    // One contour loop: its faces in order, each ray after its face.
    std::vector<LoopRay> rays;
    int length = 0;
    for (int e = static_cast<int>(first); e >= 0 && !visited[static_cast<size_t>(e)];
         e = planes[static_cast<size_t>(e)].next) {
      visited[static_cast<size_t>(e)] = true;
      if (const auto it = segments_of_ray.find(e); it != segments_of_ray.end())
        rays.push_back({length, it->second});
      ++length;
    }
    if (rays.empty()) continue;
    ++result.loops;
    std::vector<int> chosen;
    if (rays.size() == 1) {
      chosen.push_back(
          *std::min_element(rays[0].segments.begin(), rays[0].segments.end(), [&](int a, int b) {
            return segment_weight[static_cast<size_t>(a)] < segment_weight[static_cast<size_t>(b)];
          }));
    } else {
      // Start at the ray with the fewest segments: one cycle search per start segment.
      const auto fewest = std::min_element(
          rays.begin(), rays.end(),
          [](const auto& a, const auto& b) { return a.segments.size() < b.segments.size(); });
      std::rotate(rays.begin(), fewest, rays.end());
      ShortestCycle(rays, length, edges, segment_weight, discontinuity_cost, chosen);
    }
    for (size_t k = 0; k < chosen.size(); ++k) {
      result.is_true[static_cast<size_t>(chosen[k])] = true;
      if (chosen.size() < 2) continue;
      const int a = chosen[k], b = chosen[(k + 1) % chosen.size()];
      const int step = (rays[(k + 1) % rays.size()].position - rays[k].position + length) % length;
      const std::vector<int> shared = SharedPieces(edges.segments[static_cast<size_t>(a)],
                                                   edges.segments[static_cast<size_t>(b)]);
      if (step != 1 || shared.empty()) {
        result.breaks.emplace_back(a, b);
      } else {
        result.strip_pieces.insert(result.strip_pieces.end(), shared.begin(), shared.end());
      }
    }
  }
  return result;
}

}  // namespace silnet::aggregator

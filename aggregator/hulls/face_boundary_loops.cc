#include "aggregator/hulls/face_boundary_loops.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace silnet::aggregator {
namespace {

// A directed piece of the boundary, the region on its left.
struct BoundaryEdge {
  LoopPoint from, to;
};

// A trapezoid's vertical side at one lambda: its right side (`left_of_lambda`, the trapezoid
// lies before lambda) or its left side.
struct VerticalSide {
  double lambda = 0;
  bool left_of_lambda = false;
  Corner low, high;
};

// The stretches of one lambda covered by `sides` (a contiguous run of the sorted sides, all of
// one kind), zero-length sides left out and sides that meet at a vertex merged.
std::vector<std::pair<Corner, Corner>> Stretches(std::vector<VerticalSide>::const_iterator begin,
                                                 std::vector<VerticalSide>::const_iterator end) {
  std::vector<std::pair<Corner, Corner>> stretches;
  for (auto side = begin; side != end; ++side) {
    if (side->low.vertex == side->high.vertex) continue;
    if (!stretches.empty() && stretches.back().second.vertex == side->low.vertex) {
      stretches.back().second = side->high;
    } else {
      stretches.emplace_back(side->low, side->high);
    }
  }
  return stretches;
}

// Adds the boundary edges of the trapezoids' vertical sides; false where the sides before and
// after an inner lambda do not cover the same stretches.
bool AddVerticalEdges(const std::vector<Trapezoid>& trapezoids, std::vector<BoundaryEdge>& edges) {
  std::vector<VerticalSide> sides;
  sides.reserve(2 * trapezoids.size());
  for (const Trapezoid& t : trapezoids) {
    sides.push_back({t.b, true, t.bottom_b, t.top_b});
    sides.push_back({t.a, false, t.bottom_a, t.top_a});
  }
  std::sort(sides.begin(), sides.end(), [](const VerticalSide& x, const VerticalSide& y) {
    if (x.lambda != y.lambda) return x.lambda < y.lambda;
    if (x.left_of_lambda != y.left_of_lambda) return x.left_of_lambda;
    return x.low.w < y.low.w || (x.low.w == y.low.w && x.high.w < y.high.w);
  });
  for (auto begin = sides.begin(); begin != sides.end();) {
    const double lambda = begin->lambda;
    auto split = begin;
    while (split != sides.end() && split->lambda == lambda && split->left_of_lambda)
      ++split;
    auto end = split;
    while (end != sides.end() && end->lambda == lambda)
      ++end;
    const auto before = Stretches(begin, split);
    const auto after = Stretches(split, end);
    if (lambda == 0 && before.empty()) {
      for (const auto& [low, high] : after)
        edges.push_back({{lambda, high.w, high.vertex}, {lambda, low.w, low.vertex}});
    } else if (lambda == 1 && after.empty()) {
      for (const auto& [low, high] : before)
        edges.push_back({{lambda, low.w, low.vertex}, {lambda, high.w, high.vertex}});
    } else if (before.size() != after.size() ||
               !std::equal(
                   before.begin(), before.end(), after.begin(), [](const auto& x, const auto& y) {
                     return x.first.vertex == y.first.vertex && x.second.vertex == y.second.vertex;
                   })) {
      return false;
    }
    begin = end;
  }
  return true;
}

// The turn from direction `in` to `out`, in (-pi, pi], counter-clockwise positive.
double Turn(const BoundaryEdge& in, const BoundaryEdge& out) {
  const double ix = in.to.lambda - in.from.lambda, iw = in.to.w - in.from.w;
  const double ox = out.to.lambda - out.from.lambda, ow = out.to.w - out.from.w;
  return std::atan2(ix * ow - iw * ox, ix * ox + iw * ow);
}

}  // namespace

bool FaceBoundaryLoops(const std::vector<Trapezoid>& trapezoids,
                       std::vector<std::vector<LoopPoint>>& loops) {
  loops.clear();
  std::vector<BoundaryEdge> edges;
  edges.reserve(2 * trapezoids.size() + 8);
  for (const Trapezoid& t : trapezoids) {
    if (t.bottom_a.vertex != t.bottom_b.vertex)
      edges.push_back(
          {{t.a, t.bottom_a.w, t.bottom_a.vertex}, {t.b, t.bottom_b.w, t.bottom_b.vertex}});
    if (t.top_a.vertex != t.top_b.vertex)
      edges.push_back({{t.b, t.top_b.w, t.top_b.vertex}, {t.a, t.top_a.w, t.top_a.vertex}});
  }
  if (!AddVerticalEdges(trapezoids, edges)) return false;
  // Edges by their first vertex.
  std::vector<std::pair<int, int>> by_from(edges.size());
  for (size_t e = 0; e < edges.size(); ++e)
    by_from[e] = {edges[e].from.vertex, static_cast<int>(e)};
  std::sort(by_from.begin(), by_from.end());
  std::vector<char> used(edges.size(), 0);
  std::vector<LoopPoint> loop;
  for (size_t first = 0; first < edges.size(); ++first) {
    if (used[first]) continue;
    loop.clear();
    const int start = edges[first].from.vertex;
    size_t e = first;
    while (true) {
      used[e] = 1;
      loop.push_back(edges[e].from);
      const int vertex = edges[e].to.vertex;
      if (vertex == start) break;
      // Where several boundary edges leave a vertex (loops touching there), the one turning
      // most to the left keeps this loop apart from the other.
      int next = -1;
      double best = 0;
      for (auto it = std::lower_bound(by_from.begin(), by_from.end(), std::pair(vertex, -1));
           it != by_from.end() && it->first == vertex; ++it) {
        if (used[static_cast<size_t>(it->second)]) continue;
        const double turn = Turn(edges[e], edges[static_cast<size_t>(it->second)]);
        if (next < 0 || turn > best) {
          next = it->second;
          best = turn;
        }
      }
      if (next < 0) return false;  // the boundary ends here
      e = static_cast<size_t>(next);
    }
    std::vector<LoopPoint> named;
    for (const LoopPoint& point : loop) {
      if (point.vertex >= 0) named.push_back(point);
    }
    if (named.size() < 3) return false;
    loops.push_back(std::move(named));
  }
  return true;
}

}  // namespace silnet::aggregator

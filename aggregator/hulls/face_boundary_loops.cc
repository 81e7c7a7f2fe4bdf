#include "aggregator/hulls/face_boundary_loops.h"

#include <Eigen/Core>
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
// one kind), zero-length sides left out and sides that meet at a vertex merged, into
// `stretches`.
void Stretches(std::vector<VerticalSide>::const_iterator begin,
               std::vector<VerticalSide>::const_iterator end,
               std::vector<std::pair<Corner, Corner>>& stretches) {
  stretches.clear();
  for (auto side = begin; side != end; ++side) {
    if (side->low.vertex == side->high.vertex) continue;
    if (!stretches.empty() && stretches.back().second.vertex == side->low.vertex) {
      stretches.back().second = side->high;
    } else {
      stretches.emplace_back(side->low, side->high);
    }
  }
}

// Adds the boundary edges at one lambda: where the trapezoids before it (right sides,
// `before`) and after it (left sides, `after`) cover different stretches, the difference,
// upwards where only `before` covers it (the region lies to its left), downwards where only
// `after` does. Inside the chart that happens only at a sliver of a slab (a line shorter than
// the sweep keeps); the cuts at its ends are then kept as vertices, into `kept`.
void AddDifferenceEdges(double lambda, const std::vector<std::pair<Corner, Corner>>& before,
                        const std::vector<std::pair<Corner, Corner>>& after,
                        std::vector<BoundaryEdge>& edges, std::vector<int>& kept) {
  const bool inner = lambda > 0 && lambda < 1;
  if (before.empty() || after.empty()) {
    // The stretches themselves, in their own order even where rounding inverted one.
    for (const auto& [low, high] : before.empty() ? after : before) {
      const LoopPoint from{lambda, low.w, low.vertex}, to{lambda, high.w, high.vertex};
      edges.push_back(before.empty() ? BoundaryEdge{to, from} : BoundaryEdge{from, to});
      if (inner) kept.insert(kept.end(), {low.vertex, high.vertex});
    }
    return;
  }
  std::vector<Corner> points;
  for (const auto* stretches : {&before, &after}) {
    for (const auto& [low, high] : *stretches) {
      points.push_back(low);
      points.push_back(high);
    }
  }
  std::sort(points.begin(), points.end(), [](const Corner& x, const Corner& y) {
    return x.w < y.w || (x.w == y.w && x.vertex < y.vertex);
  });
  points.erase(std::unique(points.begin(), points.end(),
                           [](const Corner& x, const Corner& y) { return x.vertex == y.vertex; }),
               points.end());
  const auto index = [&points](int vertex) {
    return static_cast<size_t>(
        std::find_if(points.begin(), points.end(),
                     [vertex](const Corner& c) { return c.vertex == vertex; }) -
        points.begin());
  };
  // Coverage of the piece between points k and k + 1: +1 for before, +2 for after.
  std::vector<int> coverage(points.size(), 0);
  for (const auto& [stretches, bit] : {std::pair(&before, 1), std::pair(&after, 2)}) {
    for (const auto& [low, high] : *stretches) {
      for (size_t k = index(low.vertex); k < index(high.vertex); ++k)
        coverage[k] |= bit;
    }
  }
  for (size_t k = 0; k + 1 < points.size(); ++k) {
    if (coverage[k] != 1 && coverage[k] != 2) continue;
    const LoopPoint low{lambda, points[k].w, points[k].vertex};
    const LoopPoint high{lambda, points[k + 1].w, points[k + 1].vertex};
    edges.push_back(coverage[k] == 1 ? BoundaryEdge{low, high} : BoundaryEdge{high, low});
    if (inner) {
      kept.push_back(low.vertex);
      kept.push_back(high.vertex);
    }
  }
}

// Buffers FaceBoundaryLoops reuses (one set per thread).
struct LoopScratch {
  std::vector<BoundaryEdge> edges;
  std::vector<int> kept;
  std::vector<VerticalSide> sides;
  std::vector<std::pair<Corner, Corner>> before, after;
  std::vector<std::pair<int, int>> by_from;
  std::vector<char> used;
  std::vector<LoopPoint> loop;
};

// Adds the boundary edges of the trapezoids' vertical sides (at lambda 0 and 1, and at the
// slivers inside) to scratch.edges, the cuts they end at to scratch.kept.
void AddVerticalEdges(const std::vector<Trapezoid>& trapezoids, LoopScratch& scratch) {
  std::vector<VerticalSide>& sides = scratch.sides;
  sides.clear();
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
    std::vector<std::pair<Corner, Corner>>& before = scratch.before;
    std::vector<std::pair<Corner, Corner>>& after = scratch.after;
    Stretches(begin, split, before);
    Stretches(split, end, after);
    const auto same = [](const auto& x, const auto& y) {
      return x.first.vertex == y.first.vertex && x.second.vertex == y.second.vertex;
    };
    if (before.size() != after.size() ||
        !std::equal(before.begin(), before.end(), after.begin(), same)) {
      AddDifferenceEdges(lambda, before, after, scratch.edges, scratch.kept);
    }
    begin = end;
  }
}

// The turn from direction `in` to `out`, in (-pi, pi], counter-clockwise positive.
double Turn(const BoundaryEdge& in, const BoundaryEdge& out) {
  const double ix = in.to.lambda - in.from.lambda, iw = in.to.w - in.from.w;
  const double ox = out.to.lambda - out.from.lambda, ow = out.to.w - out.from.w;
  return std::atan2(ix * ow - iw * ox, ix * ox + iw * ow);
}

// Points closer than this in the chart (w scaled to the chart's range) are one point.
constexpr double kSamePoint = 1e-12;
// A loop folds back on itself where its turn's sine is below this.
constexpr double kFoldSine = 1e-9;

// Removes the points where `loop` repeats the previous point or folds back on itself (the
// zero-area spike a slab sliver leaves), w scaled by 1 / `w_range`.
void RemoveSpikes(std::vector<LoopPoint>& loop, double w_range) {
  const auto chart = [w_range](const LoopPoint& p) {
    return Eigen::Vector2d(p.lambda, p.w / w_range);
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t k = 0; k < loop.size() && loop.size() >= 3; ++k) {
      const size_t n = loop.size();
      const Eigen::Vector2d in = chart(loop[k]) - chart(loop[(k + n - 1) % n]);
      const Eigen::Vector2d out = chart(loop[(k + 1) % n]) - chart(loop[k]);
      const double cross = in.x() * out.y() - in.y() * out.x();
      if (in.norm() <= kSamePoint ||
          (std::abs(cross) <= kFoldSine * in.norm() * out.norm() && in.dot(out) < 0)) {
        loop.erase(loop.begin() + static_cast<std::ptrdiff_t>(k));
        changed = true;
      }
    }
  }
}

}  // namespace

bool FaceBoundaryLoops(const std::vector<Trapezoid>& trapezoids, double w_range,
                       std::vector<std::vector<LoopPoint>>& loops) {
  loops.clear();
  thread_local LoopScratch scratch;
  std::vector<BoundaryEdge>& edges = scratch.edges;
  edges.clear();
  for (const Trapezoid& t : trapezoids) {
    if (t.bottom_a.vertex != t.bottom_b.vertex)
      edges.push_back(
          {{t.a, t.bottom_a.w, t.bottom_a.vertex}, {t.b, t.bottom_b.w, t.bottom_b.vertex}});
    if (t.top_a.vertex != t.top_b.vertex)
      edges.push_back({{t.b, t.top_b.w, t.top_b.vertex}, {t.a, t.top_a.w, t.top_a.vertex}});
  }
  std::vector<int>& kept = scratch.kept;
  kept.clear();
  AddVerticalEdges(trapezoids, scratch);
  std::sort(kept.begin(), kept.end());
  // Edges by their first vertex.
  std::vector<std::pair<int, int>>& by_from = scratch.by_from;
  by_from.resize(edges.size());
  for (size_t e = 0; e < edges.size(); ++e)
    by_from[e] = {edges[e].from.vertex, static_cast<int>(e)};
  std::sort(by_from.begin(), by_from.end());
  std::vector<char>& used = scratch.used;
  used.assign(edges.size(), 0);
  std::vector<LoopPoint>& loop = scratch.loop;
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
      bool best_known = false;  // the turn matters only where another edge competes
      for (auto it = std::lower_bound(by_from.begin(), by_from.end(), std::pair(vertex, -1));
           it != by_from.end() && it->first == vertex; ++it) {
        if (used[static_cast<size_t>(it->second)]) continue;
        if (next < 0) {
          next = it->second;
          continue;
        }
        if (!best_known) best = Turn(edges[e], edges[static_cast<size_t>(next)]);
        best_known = true;
        const double turn = Turn(edges[e], edges[static_cast<size_t>(it->second)]);
        if (turn > best) {
          next = it->second;
          best = turn;
        }
      }
      if (next < 0) return false;  // the boundary ends here
      e = static_cast<size_t>(next);
    }
    std::vector<LoopPoint> named;
    for (const LoopPoint& point : loop) {
      if (point.vertex >= 0 || std::binary_search(kept.begin(), kept.end(), point.vertex))
        named.push_back(point);
    }
    RemoveSpikes(named, w_range);
    if (named.size() >= 3) loops.push_back(std::move(named));  // else it had no area
  }
  return true;
}

}  // namespace silnet::aggregator

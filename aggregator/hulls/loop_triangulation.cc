#include "aggregator/hulls/loop_triangulation.h"

#include <absl/container/inlined_vector.h>
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>

namespace silnet::aggregator {
namespace {

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// True if `p` lies inside triangle (a, b, c) or on its sides, whatever its orientation.
bool InTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                const Eigen::Vector2d& p) {
  const double ab = Cross(a, b, p), bc = Cross(b, c, p), ca = Cross(c, a, p);
  return (ab >= 0 && bc >= 0 && ca >= 0) || (ab <= 0 && bc <= 0 && ca <= 0);
}

double SignedArea(const std::vector<Eigen::Vector2d>& loop) {
  double area = 0;
  for (size_t k = 1; k + 1 < loop.size(); ++k)
    area += Cross(loop[0], loop[k], loop[k + 1]);
  return 0.5 * area;
}

// True if `p` lies strictly inside `loop` (even-odd), false outside; nullopt on its boundary.
std::optional<bool> StrictlyInside(const std::vector<Eigen::Vector2d>& loop,
                                   const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t k = 0; k < loop.size(); ++k) {
    const Eigen::Vector2d& a = loop[k];
    const Eigen::Vector2d& b = loop[(k + 1) % loop.size()];
    if (Cross(a, b, p) == 0 && p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) &&
        p.y() >= std::min(a.y(), b.y()) && p.y() <= std::max(a.y(), b.y()))
      return std::nullopt;
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()))
      inside = !inside;
  }
  return inside;
}

// The loops' points as one doubly linked ring per outer loop, holes spliced in by bridges,
// then clipped ear by ear.
class EarClipper {
 public:
  // `rounding`: the turn (twice a triangle's area) that counts as flat once only flat ears
  // are left; `nodes`: room made for this many (the rings' points, two more per hole).
  EarClipper(std::vector<std::array<int, 3>>& triangles, double rounding, size_t nodes)
      : triangles_(triangles), rounding_(rounding) {
    nodes_.reserve(nodes);
  }

  // Adds a loop's points as a ring; returns its first node.
  int AddRing(const std::vector<Eigen::Vector2d>& loop, int first_index) {
    const int start = static_cast<int>(nodes_.size());
    const int n = static_cast<int>(loop.size());
    for (int k = 0; k < n; ++k) {
      nodes_.push_back({loop[static_cast<size_t>(k)], first_index + k, start + (k + n - 1) % n,
                        start + (k + 1) % n});
    }
    return start;
  }

  // Joins the hole ring starting at `hole` to the outer ring through `outer`; false if no
  // bridge is found (the hole is not inside).
  bool JoinHole(int hole, int outer) {
    const int leftmost = Leftmost(hole);
    const int bridge = FindBridge(leftmost, outer);
    if (bridge < 0) return false;
    Split(bridge, leftmost);
    return true;
  }

  // Clips the ring through `start` into triangles; false if it gets stuck.
  bool Clip(int start) {
    int ear = start, stop = start;
    bool allow_flat = false;
    while (Prev(ear) != Next(ear)) {
      const int prev = Prev(ear), next = Next(ear);
      if (IsEar(ear, allow_flat)) {
        triangles_.push_back({nodes_[static_cast<size_t>(prev)].index,
                              nodes_[static_cast<size_t>(ear)].index,
                              nodes_[static_cast<size_t>(next)].index});
        Remove(ear);
        ear = Next(next);
        stop = ear;
        allow_flat = false;
        continue;
      }
      ear = next;
      if (ear == stop) {
        if (allow_flat) return false;
        allow_flat = true;  // only flat ears are left: clip them as zero-area triangles
      }
    }
    return true;
  }

 private:
  struct Node {
    Eigen::Vector2d x;
    int index;
    int prev, next;
  };

  const Eigen::Vector2d& At(int node) const { return nodes_[static_cast<size_t>(node)].x; }
  int Prev(int node) const { return nodes_[static_cast<size_t>(node)].prev; }
  int Next(int node) const { return nodes_[static_cast<size_t>(node)].next; }

  void Remove(int node) {
    const int prev = Prev(node), next = Next(node);
    nodes_[static_cast<size_t>(prev)].next = next;
    nodes_[static_cast<size_t>(next)].prev = prev;
  }

  // The node with the smallest x of the ring through `start` (smallest y among ties).
  int Leftmost(int start) const {
    int best = start;
    for (int p = Next(start); p != start; p = Next(p)) {
      const Eigen::Vector2d& x = At(p);
      const Eigen::Vector2d& b = At(best);
      if (x.x() < b.x() || (x.x() == b.x() && x.y() < b.y())) best = p;
    }
    return best;
  }

  // True if the vertex bends left (counter-clockwise), so it can be an ear.
  bool Convex(int node) const { return Cross(At(Prev(node)), At(node), At(Next(node))) > 0; }

  // True if (prev, ear, next) can be cut off: it turns left (or is flat, when allowed) and no
  // vertex that could block it lies in it (vertices at its corners' positions, the copies a
  // bridge makes, do not block).
  bool IsEar(int ear, bool allow_flat) const {
    const Eigen::Vector2d& a = At(Prev(ear));
    const Eigen::Vector2d& b = At(ear);
    const Eigen::Vector2d& c = At(Next(ear));
    const double turn = Cross(a, b, c);
    if (allow_flat ? turn < -rounding_ : turn <= 0) return false;
    for (int p = Next(Next(ear)); p != Prev(ear); p = Next(p)) {
      const Eigen::Vector2d& x = At(p);
      if (x == a || x == b || x == c) continue;
      if (!Convex(p) && InTriangle(a, b, c, x)) return false;
    }
    return true;
  }

  // True if the diagonal from `node` towards `target` starts inside the ring.
  bool LocallyInside(int node, const Eigen::Vector2d& target) const {
    const Eigen::Vector2d& x = At(node);
    const Eigen::Vector2d& prev = At(Prev(node));
    const Eigen::Vector2d& next = At(Next(node));
    if (Cross(prev, x, next) >= 0)
      return Cross(x, next, target) >= 0 && Cross(x, target, prev) >= 0;
    return Cross(x, target, prev) > 0 || Cross(x, next, target) > 0;
  }

  // The outer ring's node to connect the hole's leftmost node `hole` to: the ray from it to
  // the left meets the ring's nearest edge; the edge's left end, or the ring vertex inside the
  // triangle of hole, hit and that end that is seen at the smallest angle.
  int FindBridge(int hole, int outer) const {
    const Eigen::Vector2d& h = At(hole);
    double hit = -std::numeric_limits<double>::infinity();
    int m = -1;
    int p = outer;
    do {
      const Eigen::Vector2d& a = At(p);
      const Eigen::Vector2d& b = At(Next(p));
      // Only edges running downwards face the hole from its left on a counter-clockwise ring.
      if (h.y() <= a.y() && h.y() >= b.y() && a.y() != b.y()) {
        const double x = a.x() + (h.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
        if (x <= h.x() && x > hit) {
          hit = x;
          m = a.x() < b.x() ? p : Next(p);
          if (x == h.x()) return m;  // the hole touches the edge
        }
      }
      p = Next(p);
    } while (p != outer);
    if (m < 0) return -1;
    const Eigen::Vector2d hit_point(hit, h.y());
    const Eigen::Vector2d corner = At(m);
    double best_tan = std::numeric_limits<double>::infinity();
    const int stop = m;
    p = m;
    do {
      const Eigen::Vector2d& x = At(p);
      if (h.x() >= x.x() && x.x() >= corner.x() && h.x() != x.x() &&
          InTriangle(h, hit_point, corner, x)) {
        const double tan = std::abs(h.y() - x.y()) / (h.x() - x.x());
        if (LocallyInside(p, h) && (tan < best_tan || (tan == best_tan && x.x() > At(m).x()))) {
          m = p;
          best_tan = tan;
        }
      }
      p = Next(p);
    } while (p != stop);
    return m;
  }

  // Links `a` (outer ring) to `b` (hole) by a bridge there and back: a -> b, the hole, b' -> a'.
  void Split(int a, int b) {
    const int a2 = static_cast<int>(nodes_.size());
    const int b2 = a2 + 1;
    nodes_.push_back(nodes_[static_cast<size_t>(a)]);
    nodes_.push_back(nodes_[static_cast<size_t>(b)]);
    const int an = Next(a), bp = Prev(b);
    nodes_[static_cast<size_t>(a)].next = b;
    nodes_[static_cast<size_t>(b)].prev = a;
    nodes_[static_cast<size_t>(a2)].next = an;
    nodes_[static_cast<size_t>(an)].prev = a2;
    nodes_[static_cast<size_t>(b2)].next = a2;
    nodes_[static_cast<size_t>(a2)].prev = b2;
    nodes_[static_cast<size_t>(bp)].next = b2;
    nodes_[static_cast<size_t>(b2)].prev = bp;
  }

  absl::InlinedVector<Node, 16> nodes_;  // most faces have fewer points: no allocation
  std::vector<std::array<int, 3>>& triangles_;
  double rounding_;
};

}  // namespace

LoopTriangulation TriangulateLoops(const std::vector<std::vector<Eigen::Vector2d>>& loops) {
  LoopTriangulation result;
  // Most faces have one loop: these stay off the heap.
  absl::InlinedVector<int, 4> first(loops.size());
  absl::InlinedVector<double, 4> areas(loops.size());
  absl::InlinedVector<size_t, 4> outers, holes;
  double region_area = 0, scale = 0;
  int count = 0;
  // Rounding errors of areas are relative to the extent of the points, not to the region's
  // area (a sliver between far points).
  Eigen::AlignedBox2d box;
  for (const auto& loop : loops) {
    for (const Eigen::Vector2d& x : loop)
      box.extend(x);
  }
  const double rounding = 1e-12 * (loops.empty() ? 0.0 : box.sizes().squaredNorm());
  for (size_t k = 0; k < loops.size(); ++k) {
    first[k] = count;
    count += static_cast<int>(loops[k].size());
    if (loops[k].size() < 3) {
      result.reason = fmt::format("loop {} has {} points", k, loops[k].size());
      return result;
    }
    areas[k] = SignedArea(loops[k]);
    region_area += areas[k];
    scale += std::abs(areas[k]);
    if (areas[k] > 0) {
      outers.push_back(k);
    } else if (areas[k] < 0) {
      holes.push_back(k);
    } else {
      result.reason = fmt::format("loop {} encloses no area", k);
      return result;
    }
  }
  // Each hole to the smallest outer loop around it (none allocated for a face without holes).
  std::vector<std::vector<size_t>> holes_of(holes.empty() ? 0 : loops.size());
  for (const size_t hole : holes) {
    size_t owner = loops.size();
    if (outers.size() == 1) {
      owner = outers[0];
    } else {
      for (const Eigen::Vector2d& x : loops[hole]) {
        bool decided = true;
        for (const size_t outer : outers) {
          const std::optional<bool> inside = StrictlyInside(loops[outer], x);
          if (!inside) {
            decided = false;
            break;
          }
          if (*inside && (owner == loops.size() || areas[outer] < areas[owner])) owner = outer;
        }
        if (decided) break;
        owner = loops.size();
      }
    }
    if (owner == loops.size()) {
      result.reason = fmt::format("hole {} lies in no outer loop", hole);
      return result;
    }
    holes_of[owner].push_back(hole);
  }
  // Each hole's bridge adds two points; a ring of n points makes n - 2 triangles.
  const size_t nodes = static_cast<size_t>(count) + 2 * holes.size();
  result.triangles.reserve(nodes);
  EarClipper clipper(result.triangles, 2 * rounding, nodes);
  for (const size_t outer : outers) {
    const int ring = clipper.AddRing(loops[outer], first[outer]);
    std::vector<std::pair<double, int>> hole_rings;
    for (const size_t hole : holes_of.empty() ? std::span<const size_t>() : holes_of[outer]) {
      const int start = clipper.AddRing(loops[hole], first[hole]);
      const auto leftmost = std::min_element(
          loops[hole].begin(), loops[hole].end(),
          [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); });
      hole_rings.emplace_back(leftmost->x(), start);
    }
    // Left to right: the ray from a hole's leftmost point meets only loops already joined.
    std::sort(hole_rings.begin(), hole_rings.end());
    for (const auto& [x, node] : hole_rings) {
      if (!clipper.JoinHole(node, ring)) {
        result.reason = "a hole could not be joined to its outer loop";
        return result;
      }
    }
    if (!clipper.Clip(ring)) {
      result.reason = "no ear left to clip: the loops cross or are inverted";
      return result;
    }
  }
  double triangles_area = 0;
  for (const auto& t : result.triangles) {
    const auto point = [&](int index) {
      const auto loop = std::upper_bound(first.begin(), first.end(), index) - first.begin() - 1;
      return loops[static_cast<size_t>(loop)]
                  [static_cast<size_t>(index - first[static_cast<size_t>(loop)])];
    };
    const double area = 0.5 * Cross(point(t[0]), point(t[1]), point(t[2]));
    if (area < -rounding) {
      result.reason = "a triangle is inverted: the loops cross";
      return result;
    }
    triangles_area += area;
  }
  if (std::abs(triangles_area - region_area) > 1e-9 * scale + rounding) {
    result.reason =
        fmt::format("the triangles cover {} of the region's area {}", triangles_area, region_area);
    return result;
  }
  result.success = true;
  return result;
}

}  // namespace silnet::aggregator

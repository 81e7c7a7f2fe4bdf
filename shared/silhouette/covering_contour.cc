#include "shared/silhouette/covering_contour.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

namespace silnet {
namespace {

using Vec = Eigen::Vector2d;

// Kept points closer than this are merged (pixels).
constexpr double kSamePoint = 1e-3;
// A kept point whose edges turn by less than asin of this is dropped.
constexpr double kStraight = 1e-6;

double Cross(const Vec& a, const Vec& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Distance from p to the segment a-b.
double PointSegmentDistance(const Vec& p, const Vec& a, const Vec& b) {
  const Vec ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

// Distance between segments a-b and c-d (0 when they cross).
double SegmentDistance(const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 0.0;
  return std::min({PointSegmentDistance(a, c, d), PointSegmentDistance(b, c, d),
                   PointSegmentDistance(c, a, b), PointSegmentDistance(d, a, b)});
}

// An edge of a simplified ring: the chord between two kept outline points, and the span
// (index into the ring's breaks) it replaces.
struct Edge {
  Vec a, b;
  int span = 0;
};

// One ring being simplified: its traced points and the sorted outline indices it keeps
// (`breaks_`); span s runs from breaks_[s] to the next break.
class RingSimplifier {
 public:
  RingSimplifier(const TracedRing& ring, const CoveringOptions& options) : options_(options) {
    n_ = static_cast<int>(ring.outline.size());
    for (int i = 0; i < n_; ++i) {
      centres_.push_back(ring.centres[static_cast<size_t>(i)].cast<double>());
      outline_.push_back(ring.outline[static_cast<size_t>(i)].cast<double>());
    }
    if (ring.background.size() == 2 * ring.outline.size()) {
      for (const Eigen::Vector2f& b : ring.background)
        background_.push_back(b.cast<double>());
    }
    if (n_ < 4) {
      for (int i = 0; i < n_; ++i)
        breaks_.push_back(i);
      return;
    }
    int far = 0;
    for (int i = 1; i < n_; ++i) {
      if ((Point(i) - Point(0)).squaredNorm() > (Point(far) - Point(0)).squaredNorm()) far = i;
    }
    if (far == 0) far = n_ / 2;
    breaks_ = {0, far};
    std::vector<std::pair<int, int>> spans = {{0, far}, {far, n_}};
    Split(spans);
  }

  // Rebuilds the edges from the current breaks and clears the marks.
  void Build() {
    edges_.clear();
    bad_.assign(breaks_.size(), 0);
    for (size_t s = 0; s < breaks_.size(); ++s)
      edges_.push_back({Point(breaks_[s]), Point(End(s)), static_cast<int>(s)});
  }

  const std::vector<Edge>& edges() const { return edges_; }

  // Marks the span of `edge` for splitting.
  void MarkBad(const Edge& edge) { bad_[static_cast<size_t>(edge.span)] = 1; }

  // Splits every marked span that has an outline point between its ends at the point farthest
  // from its chord (then as Split); returns true if any span changed.
  bool Refine() {
    std::vector<std::pair<int, int>> spans;
    std::vector<int> added;
    for (size_t s = 0; s < breaks_.size() && s < bad_.size(); ++s) {
      if (!bad_[s]) continue;
      const int start = breaks_[s], end = End(s);
      if (end - start < 2) continue;
      const Vec& a = Point(start);
      const Vec& b = Point(end);
      int split = (start + end) / 2;
      double farthest = -1;
      for (int i = start + 1; i < end; ++i) {
        const double d = PointSegmentDistance(Point(i), a, b);
        if (d > farthest) {
          farthest = d;
          split = i;
        }
      }
      added.push_back(split % n_);
      spans.emplace_back(start, split);
      spans.emplace_back(split, end);
    }
    if (spans.empty()) return false;
    breaks_.insert(breaks_.end(), added.begin(), added.end());
    Split(spans);
    return true;
  }

  // The kept outline points, without repeated points and without points where the ring runs
  // straight on (the polygon stays the same).
  std::vector<Eigen::Vector2f> Result() const {
    std::vector<Vec> ring;
    ring.reserve(breaks_.size());
    for (const int b : breaks_) {
      if (ring.empty() || (Point(b) - ring.back()).norm() > kSamePoint) ring.push_back(Point(b));
    }
    while (ring.size() > 1 && (ring.front() - ring.back()).norm() <= kSamePoint)
      ring.pop_back();
    for (bool removed = true; removed && ring.size() > 3;) {
      removed = false;
      for (size_t i = 0; i < ring.size() && ring.size() > 3; ++i) {
        const Vec& a = ring[(i + ring.size() - 1) % ring.size()];
        const Vec& c = ring[(i + 1) % ring.size()];
        const Vec u = ring[i] - a, v = c - ring[i];
        if (std::abs(Cross(u, v)) <= kStraight * u.norm() * v.norm() && u.dot(v) > 0) {
          ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
          removed = true;
        }
      }
    }
    std::vector<Eigen::Vector2f> out;
    out.reserve(ring.size());
    for (const Vec& p : ring)
      out.push_back(p.cast<float>());
    return out;
  }

 private:
  const Vec& Point(int i) const { return outline_[static_cast<size_t>(Wrap(i))]; }
  const Vec& Centre(int i) const { return centres_[static_cast<size_t>(Wrap(i))]; }
  int Wrap(int i) const { return ((i % n_) + n_) % n_; }
  // Last outline index of span s, unwrapped (> its first).
  int End(size_t s) const {
    const int end = breaks_[(s + 1) % breaks_.size()];
    return end > breaks_[s] ? end : end + n_;
  }

  // The outline index strictly inside span [start, end] (unwrapped) where it must be split for
  // its chord to keep the covering conditions, or -1 if it keeps them (or is one step).
  int WorstPoint(int start, int end) const {
    if (end - start < 2) return -1;
    const Vec& a = Point(start);
    const Vec d = Point(end) - a;
    const double length = d.norm();
    if (length < 1e-9) return (start + end) / 2;
    // Signed distance inside the chord (the silhouette lies on its left).
    auto inside = [&](const Vec& p) { return Cross(d, p - a) / length; };
    // The worst excess, and whether it asks the chord to move out (a pixel centre too close)
    // or in (a background centre or outline point too far inside).
    double worst_excess = 0;
    bool move_out = false;
    auto consider = [&](double excess, bool out) {
      if (excess > worst_excess) {
        worst_excess = excess;
        move_out = out;
      }
    };
    for (int i = start - 1; i <= end + 1; ++i)
      consider(options_.margin_px - inside(Centre(i)), true);
    for (int i = start; i <= end && !background_.empty(); ++i) {
      for (int j = 0; j < 2; ++j) {
        const Vec& b = background_[static_cast<size_t>(2 * Wrap(i) + j)];
        if (std::isfinite(b.x())) consider(inside(b) - options_.background_slack_px, false);
      }
    }
    if (worst_excess <= 0) return -1;
    // Split at the outline point farthest out (in) from the chord: the new chords move that way.
    int worst = start + 1;
    double extreme = -1e300;
    for (int i = start + 1; i < end; ++i) {
      const double depth = move_out ? -inside(Point(i)) : inside(Point(i));
      if (depth > extreme) {
        extreme = depth;
        worst = i;
      }
    }
    return worst;
  }

  // Splits the given spans (unwrapped index pairs) recursively until each keeps the covering
  // conditions; adds the new breaks and sorts them.
  void Split(std::vector<std::pair<int, int>>& spans) {
    while (!spans.empty()) {
      const auto [start, end] = spans.back();
      spans.pop_back();
      const int split = WorstPoint(start, end);
      if (split < 0) continue;
      breaks_.push_back(split % n_);
      spans.emplace_back(start, split);
      spans.emplace_back(split, end);
    }
    std::sort(breaks_.begin(), breaks_.end());
    breaks_.erase(std::unique(breaks_.begin(), breaks_.end()), breaks_.end());
  }

  const CoveringOptions& options_;
  std::vector<Vec> centres_, outline_;
  std::vector<Vec> background_;  // two per outline index, or none
  int n_ = 0;
  std::vector<int> breaks_;
  std::vector<char> bad_;  // per span
  std::vector<Edge> edges_;
};

// Marks the spans of every two non-adjacent edges (of any rings) closer than `clearance`.
void MarkCloseEdges(std::vector<RingSimplifier>& rings, double clearance) {
  struct Ref {
    double x0, x1, y0, y1;
    int ring, edge;
  };
  std::vector<Ref> refs;
  for (size_t r = 0; r < rings.size(); ++r) {
    const std::vector<Edge>& edges = rings[r].edges();
    for (size_t e = 0; e < edges.size(); ++e) {
      const Edge& edge = edges[e];
      refs.push_back({std::min(edge.a.x(), edge.b.x()), std::max(edge.a.x(), edge.b.x()),
                      std::min(edge.a.y(), edge.b.y()), std::max(edge.a.y(), edge.b.y()),
                      static_cast<int>(r), static_cast<int>(e)});
    }
  }
  std::sort(refs.begin(), refs.end(), [](const Ref& a, const Ref& b) { return a.x0 < b.x0; });
  for (size_t i = 0; i < refs.size(); ++i) {
    const Ref& a = refs[i];
    for (size_t j = i + 1; j < refs.size() && refs[j].x0 <= a.x1 + clearance; ++j) {
      const Ref& b = refs[j];
      if (b.y0 > a.y1 + clearance || a.y0 > b.y1 + clearance) continue;
      if (a.ring == b.ring) {
        const int m = static_cast<int>(rings[static_cast<size_t>(a.ring)].edges().size());
        const int gap = std::abs(a.edge - b.edge);
        if (gap <= 1 || gap == m - 1) continue;
      }
      RingSimplifier& ra = rings[static_cast<size_t>(a.ring)];
      RingSimplifier& rb = rings[static_cast<size_t>(b.ring)];
      const Edge& ea = ra.edges()[static_cast<size_t>(a.edge)];
      const Edge& eb = rb.edges()[static_cast<size_t>(b.edge)];
      if (SegmentDistance(ea.a, ea.b, eb.a, eb.b) < clearance) {
        ra.MarkBad(ea);
        rb.MarkBad(eb);
      }
    }
  }
}

}  // namespace

std::vector<std::vector<Eigen::Vector2f>> SimplifyCovering(const std::vector<TracedRing>& rings,
                                                           const CoveringOptions& options) {
  std::vector<RingSimplifier> simplifiers;
  simplifiers.reserve(rings.size());
  for (const TracedRing& ring : rings)
    simplifiers.emplace_back(ring, options);
  for (int round = 0; round < options.max_rounds; ++round) {
    for (RingSimplifier& ring : simplifiers)
      ring.Build();
    MarkCloseEdges(simplifiers, options.clearance_px);
    bool changed = false;
    for (RingSimplifier& ring : simplifiers)
      changed = ring.Refine() || changed;
    if (!changed) break;
  }
  std::vector<std::vector<Eigen::Vector2f>> out;
  out.reserve(simplifiers.size());
  for (const RingSimplifier& ring : simplifiers)
    out.push_back(ring.Result());
  return out;
}

}  // namespace silnet

#include "aggregator/hulls/cone_line_stretches.h"

#include <algorithm>
#include <utility>

namespace silnet::aggregator {
namespace {

// The most cells of a view's cell index a traced edge's image may span for its crossings to
// be looked up there (8 to 32 were equally fast on the alien set, 64 slower). The viewing
// edges' rays are long: the epipolar index serves them better.
constexpr size_t kTracedEdgeCells = 16;

// The direction from view `line.seen_from`'s centre to the line's point at `t` (the line's own
// direction where that point is the centre).
Eigen::Vector3d SeenDirection(const std::vector<Eigen::Vector3d>& centres, const ConeLine& line,
                              double t) {
  const Eigen::Vector3d v =
      line.origin + t * line.direction - centres[static_cast<size_t>(line.seen_from)];
  return v.squaredNorm() > 0.0 ? v : line.direction;
}

// The parameter where a line meets cone plane `q` of a view whose centre is `to_centre` from
// the line's origin; `along` is the plane normal's dot product with the line's direction,
// non-zero.
double PlaneCrossing(const ConePlaneSet& set, const Eigen::Vector3d& to_centre, int q,
                     double along) {
  return set.Normal(q).dot(to_centre) / along;
}

// True if the point of `line` at `t` on cone plane `q` of view `other` lies on its face: the
// plane holds the whole line through the other camera's centre, so the point is on the face
// if it projects between the face's contour points.
bool OnFace(const ConePlaneSet& set, const ConeLine& line, int other, int q, double t) {
  const Eigen::Vector3d x =
      set.Projection(other) * (line.origin + t * line.direction).homogeneous();
  if (!(x.z() > 0)) return false;
  const ConePlane& face = set.Plane(q);
  const Eigen::Vector2d edge = face.q - face.p;
  const double s = (x.hnormalized() - face.p).dot(edge) / edge.squaredNorm();
  return s >= 0.0 && s < 1.0;
}

// Appends the faces of view `other` that the epipolar index offers for `range` of `line`.
void EpipolarCandidates(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                        const ConeLine& line, int other, const LineStretch& range,
                        std::vector<int>& out) {
  set.CandidateEdges(line.seen_from, other, SeenDirection(centres, line, range.lo),
                     SeenDirection(centres, line, range.hi), out);
}

// The crossings within `range` of `line` with view `other`'s cone faces that the epipolar
// index offers, sorted along the line.
void FindCrossings(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                   const ConeLine& line, int other, const LineStretch& range,
                   ConeLineBuffers* buffers) {
  buffers->candidates.clear();
  buffers->crossings.clear();
  EpipolarCandidates(set, centres, line, other, range, buffers->candidates);
  const Eigen::Vector3d to_centre = centres[static_cast<size_t>(other)] - line.origin;
  for (const int q : buffers->candidates) {
    const double along = set.Normal(q).dot(line.direction);
    if (along == 0.0) continue;
    const double t = PlaneCrossing(set, to_centre, q, along);
    if (t > range.lo && t < range.hi && OnFace(set, line, other, q, t))
      buffers->crossings.push_back({t, q, along > 0.0});
  }
  std::sort(buffers->crossings.begin(), buffers->crossings.end());
}

// The faces of view `other` `range` of `line` may cross: those its cell index files near the
// range's image where that spans at most kTracedEdgeCells cells, else those the epipolar
// index offers.
void ShortRangeCandidates(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                          const ConeLine& line, int other, const LineStretch& range,
                          std::vector<int>& out) {
  out.clear();
  const Matrix34d& projection = set.Projection(other);
  const Eigen::Vector3d a = projection * (line.origin + range.lo * line.direction).homogeneous();
  const Eigen::Vector3d b = projection * (line.origin + range.hi * line.direction).homogeneous();
  if (a.z() > 0 && b.z() > 0 &&
      set.EdgesNearSegment(other, a.hnormalized(), b.hnormalized(), kTracedEdgeCells, out)) {
    return;
  }
  EpipolarCandidates(set, centres, line, other, range, out);
}

// The stretches of `range` inside view `other`'s cone, from the sorted crossings (a line with
// none is inside throughout or not at all: one point-in-silhouette test decides).
void InsideStretches(const ConePlaneSet& set, const ConeLine& line, int other,
                     const LineStretch& range, ConeLineBuffers* buffers) {
  std::vector<LineStretch>& out = buffers->in_view;
  out.clear();
  const auto& crossings = buffers->crossings;
  bool inside = false;
  if (crossings.empty()) {
    const Eigen::Vector3d x =
        set.Projection(other) *
        (line.origin + 0.5 * (range.lo + range.hi) * line.direction).homogeneous();
    inside = x.z() > 0 && set.Contains(other, x.hnormalized());
  } else {
    inside = !crossings.front().entering;
  }
  LineStretch open = range;
  for (const auto& c : crossings) {
    if (c.entering) {
      open.lo = c.t;
      open.lo_plane = c.plane;
      inside = true;
    } else {
      if (inside) out.push_back({open.lo, c.t, open.lo_plane, c.plane});
      inside = false;
    }
  }
  if (inside) out.push_back({open.lo, range.hi, open.lo_plane, range.hi_plane});
}

// buffers->inside narrowed to its overlap with buffers->in_view.
void Intersect(ConeLineBuffers* buffers) {
  const std::vector<LineStretch>& a = buffers->inside;
  const std::vector<LineStretch>& b = buffers->in_view;
  std::vector<LineStretch>& out = buffers->both;
  out.clear();
  for (size_t i = 0, j = 0; i < a.size() && j < b.size();) {
    LineStretch both = a[i];
    if (b[j].lo > both.lo) {
      both.lo = b[j].lo;
      both.lo_plane = b[j].lo_plane;
    }
    if (b[j].hi < both.hi) {
      both.hi = b[j].hi;
      both.hi_plane = b[j].hi_plane;
    }
    if (both.hi > both.lo) out.push_back(both);
    if (a[i].hi < b[j].hi) {
      ++i;
    } else {
      ++j;
    }
  }
  std::swap(buffers->inside, out);
}

}  // namespace

std::optional<LineStretch> ClipToBox(const ConeLine& line, const WorldBox& box, LineStretch range) {
  for (int a = 0; a < 3; ++a) {
    const double o = line.origin[a], d = line.direction[a];
    if (d == 0.0) {
      if (o < box.min()[a] || o > box.max()[a]) return std::nullopt;
      continue;
    }
    const double t1 = (box.min()[a] - o) / d, t2 = (box.max()[a] - o) / d;
    const double lo = std::min(t1, t2), hi = std::max(t1, t2);
    if (lo > range.lo) {
      range.lo = lo;
      range.lo_plane = -1;
    }
    if (hi < range.hi) {
      range.hi = hi;
      range.hi_plane = -1;
    }
  }
  if (!(range.hi > range.lo)) return std::nullopt;
  return range;
}

void StretchesInsideCones(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                          const ConeLine& line, const LineStretch& range, int skip_a, int skip_b,
                          ConeLineBuffers* buffers) {
  buffers->inside.assign(1, range);
  const int views = static_cast<int>(set.Views());
  for (int other = 0; other < views && !buffers->inside.empty(); ++other) {
    if (other == skip_a || other == skip_b) continue;
    const LineStretch within{buffers->inside.front().lo, buffers->inside.back().hi, -1, -1};
    FindCrossings(set, centres, line, other, within, buffers);
    InsideStretches(set, line, other, within, buffers);
    Intersect(buffers);
  }
}

LineStretch FirstExit(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                      const ConeLine& line, LineStretch range, int skip_a, int skip_b,
                      int skip_plane, ConeLineBuffers* buffers) {
  const int views = static_cast<int>(set.Views());
  for (int other = 0; other < views; ++other) {
    if (other == skip_a || other == skip_b) continue;
    ShortRangeCandidates(set, centres, line, other, range, buffers->candidates);
    // The first leaving crossing, the lowest plane among equal parameters (FindCrossings'
    // order); a face offered twice changes nothing.
    double best = range.hi;
    int best_plane = -1;  // none yet in this view: the range's end excludes its parameter
    const Eigen::Vector3d to_centre = centres[static_cast<size_t>(other)] - line.origin;
    for (const int q : buffers->candidates) {
      const double along = set.Normal(q).dot(line.direction);
      if (!(along < 0.0) || q == skip_plane) continue;
      const double t = PlaneCrossing(set, to_centre, q, along);
      const bool first = t < best || (t == best && best_plane >= 0 && q < best_plane);
      if (!(t > range.lo) || !first || !OnFace(set, line, other, q, t)) continue;
      best = t;
      best_plane = q;
    }
    if (best_plane >= 0) {
      range.hi = best;
      range.hi_plane = best_plane;
    }
  }
  return range;
}

}  // namespace silnet::aggregator

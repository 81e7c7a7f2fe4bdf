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

// The crossings within `range` of `line` with view `other`'s cone faces, sorted along the
// line. The candidates are the faces the other view's cell index files near the stretch's
// image where that spans at most `most_cells` cells (a short stretch), else those the
// epipolar index offers.
void FindCrossings(const ConePlaneSet& set, const std::vector<Eigen::Vector3d>& centres,
                   const ConeLine& line, int other, const LineStretch& range, size_t most_cells,
                   ConeLineBuffers* buffers) {
  buffers->candidates.clear();
  buffers->crossings.clear();
  const Matrix34d& projection = set.Projection(other);
  bool near = false;
  if (most_cells > 0) {
    const Eigen::Vector3d a = projection * (line.origin + range.lo * line.direction).homogeneous();
    const Eigen::Vector3d b = projection * (line.origin + range.hi * line.direction).homogeneous();
    near = a.z() > 0 && b.z() > 0 &&
           set.EdgesNearSegment(other, a.hnormalized(), b.hnormalized(), most_cells,
                                buffers->candidates);
  }
  if (!near) {
    set.CandidateEdges(line.seen_from, other, SeenDirection(centres, line, range.lo),
                       SeenDirection(centres, line, range.hi), buffers->candidates);
  }
  const Eigen::Vector3d& other_centre = centres[static_cast<size_t>(other)];
  for (const int q : buffers->candidates) {
    const Eigen::Vector3d& normal = set.Normal(q);
    const double along = normal.dot(line.direction);
    if (along == 0.0) continue;
    const double t = normal.dot(other_centre - line.origin) / along;
    if (!(t > range.lo && t < range.hi)) continue;
    // The plane holds the whole line through the other camera's centre: the crossing is on
    // the face if it projects between the face's contour points.
    const Eigen::Vector3d x = projection * (line.origin + t * line.direction).homogeneous();
    if (!(x.z() > 0)) continue;
    const ConePlane& face = set.Plane(q);
    const Eigen::Vector2d edge = face.q - face.p;
    const double s = (x.hnormalized() - face.p).dot(edge) / edge.squaredNorm();
    if (s < 0.0 || s >= 1.0) continue;
    buffers->crossings.push_back({t, q, along > 0.0});
  }
  std::sort(buffers->crossings.begin(), buffers->crossings.end());
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
    FindCrossings(set, centres, line, other, within, 0, buffers);
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
    FindCrossings(set, centres, line, other, range, kTracedEdgeCells, buffers);
    for (const auto& c : buffers->crossings) {
      if (c.entering || c.plane == skip_plane) continue;
      range.hi = c.t;
      range.hi_plane = c.plane;
      break;
    }
  }
  return range;
}

}  // namespace silnet::aggregator

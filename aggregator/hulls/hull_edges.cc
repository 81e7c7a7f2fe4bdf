#include "aggregator/hulls/hull_edges.h"

#include <algorithm>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "aggregator/hulls/cone_line_stretches.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using PlaneTriple = std::array<int, 3>;

PlaneTriple Sorted(int a, int b, int c) {
  PlaneTriple t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

// Narrows `range` to where f0 + t f1 >= 0, naming `label` the plane that bounds it there;
// false if nothing is left.
bool Narrow(double f0, double f1, int label, LineStretch* range) {
  if (f1 == 0.0) return f0 >= 0.0;
  const double t = -f0 / f1;
  if (f1 > 0.0 && t > range->lo) {
    range->lo = t;
    range->lo_plane = label;
  } else if (f1 < 0.0 && t < range->hi) {
    range->hi = t;
    range->hi_plane = label;
  }
  return range->hi > range->lo;
}

// Narrows `range` of `line` (in cone plane `plane`) to the plane's face: the wedge between the
// rays through its contour points, bounded there by the planes before and after it.
bool NarrowToFace(const ConePlaneSet& set, const Eigen::Vector3d& centre, int plane,
                  const ConeLine& line, LineStretch* range) {
  const ConePlane& face = set.Plane(plane);
  const Eigen::Vector3d& normal = set.Normal(plane);
  const Eigen::Vector3d rp = set.Ray(face.view, face.p), rq = set.Ray(face.view, face.q);
  const Eigen::Vector3d offset = line.origin - centre;
  // Inside the wedge: (rp x X) . n >= 0 and (X x rq) . n >= 0 for X = offset + t direction.
  return Narrow(rp.cross(offset).dot(normal), rp.cross(line.direction).dot(normal), face.prev,
                range) &&
         Narrow(offset.cross(rq).dot(normal), line.direction.cross(rq).dot(normal), face.next,
                range);
}

class EdgeTracer {
 public:
  EdgeTracer(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
             const WorldBox& bounds)
      : set_(set), bounds_(bounds) {
    for (const CameraModel& camera : cameras)
      centres_.push_back(camera.Center());
  }

  void AddViewingEdge(const ViewingEdge& edge) {
    const int previous = set_.Plane(edge.plane).prev;
    const Eigen::Vector3d& centre = centres_[static_cast<size_t>(edge.view)];
    const Eigen::Vector3d direction = set_.Ray(edge.view, set_.Plane(edge.plane).p);
    const int from = End(previous, edge.plane, edge.near_plane, centre + edge.near * direction);
    const int to = End(previous, edge.plane, edge.far_plane, centre + edge.far * direction);
    if (from < 0 || to < 0) return;
    graph_.edges.push_back(
        {std::min(previous, edge.plane), std::max(previous, edge.plane), from, to});
    ++graph_.viewing_edges;
  }

  // Traces every queued line and the lines their ends lead to.
  HullEdgeGraph Finish() {
    while (!queue_.empty()) {
      const auto [a, b, vertex] = queue_.front();
      queue_.pop_front();
      TraceLine(a, b, graph_.vertices[static_cast<size_t>(vertex)].position);
    }
    return std::move(graph_);
  }

 private:
  // The vertex on planes a, b, c at `position` (found before or added now), and the lines of
  // two views' faces that leave it queued; -1 for an end the bounds box cut (c = -1).
  int End(int a, int b, int c, const Eigen::Vector3d& position) {
    if (c < 0) {
      ++graph_.open_ends;
      return -1;
    }
    const PlaneTriple key = Sorted(a, b, c);
    const auto [it, added] = vertex_.try_emplace(key, static_cast<int>(graph_.vertices.size()));
    if (added) {
      graph_.vertices.push_back({key, position});
      Queue(key[0], key[1], it->second);
      Queue(key[0], key[2], it->second);
      Queue(key[1], key[2], it->second);
    }
    return it->second;
  }

  // Queues the line of planes a < b through `vertex` if they belong to two views and it is new.
  void Queue(int a, int b, int vertex) {
    if (set_.Plane(a).view == set_.Plane(b).view) return;
    if (lines_.insert({a, b}).second) queue_.push_back({a, b, vertex});
  }

  // The hull's edges on the line where the faces of planes a and b meet, which passes through
  // the hull's vertex at `through`.
  void TraceLine(int a, int b, const Eigen::Vector3d& through) {
    ++graph_.lines;
    const int view_a = set_.Plane(a).view, view_b = set_.Plane(b).view;
    const Eigen::Vector3d& na = set_.Normal(a);
    const Eigen::Vector3d& nb = set_.Normal(b);
    const Eigen::Vector3d& ca = centres_[static_cast<size_t>(view_a)];
    const Eigen::Vector3d& cb = centres_[static_cast<size_t>(view_b)];
    const Eigen::Vector3d direction = na.cross(nb);
    const double length2 = direction.squaredNorm();
    if (!(length2 > 0.0)) return;
    // The point of both planes nearest the origin.
    const Eigen::Vector3d origin =
        (na.dot(ca) * nb.cross(direction) + nb.dot(cb) * direction.cross(na)) / length2;
    const ConeLine line{view_a, origin, direction, (through - origin).dot(direction) / length2};
    LineStretch range{-std::numeric_limits<double>::infinity(),
                      std::numeric_limits<double>::infinity()};
    if (!NarrowToFace(set_, ca, a, line, &range) || !NarrowToFace(set_, cb, b, line, &range))
      return;
    const std::optional<LineStretch> boxed = ClipToBox(line, bounds_, range);
    if (!boxed) return;
    StretchesInsideCones(set_, centres_, line, *boxed, view_a, view_b, &buffers_);
    const std::vector<LineStretch> stretches = buffers_.inside;
    for (const LineStretch& s : stretches) {
      const int from = End(a, b, s.lo_plane, origin + s.lo * direction);
      const int to = End(a, b, s.hi_plane, origin + s.hi * direction);
      if (from >= 0 && to >= 0) graph_.edges.push_back({a, b, from, to});
    }
  }

  const ConePlaneSet& set_;
  const WorldBox& bounds_;
  std::vector<Eigen::Vector3d> centres_;
  HullEdgeGraph graph_;
  std::map<PlaneTriple, int> vertex_;
  std::set<std::pair<int, int>> lines_;
  std::deque<std::array<int, 3>> queue_;  // planes a < b and the vertex that queued them
  ConeLineBuffers buffers_;
};

}  // namespace

HullEdgeGraph TraceHullEdges(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                             const WorldBox& bounds,
                             const std::vector<ViewingEdge>& viewing_edges) {
  SILNET_CHECK(cameras.size() == set.Views());
  EdgeTracer tracer(cameras, set, bounds);
  for (const ViewingEdge& edge : viewing_edges)
    tracer.AddViewingEdge(edge);
  return tracer.Finish();
}

}  // namespace silnet::aggregator

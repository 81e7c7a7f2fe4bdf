#include "aggregator/hulls/hull_edges.h"

#include <absl/container/flat_hash_map.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>

#include "aggregator/hulls/cone_line_stretches.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// Where the line origin + t direction (t >= 0) leaves plane `plane`'s face through the rays
// of its contour points: range.hi narrowed, `hi_plane` the plane beyond that ray.
void NarrowToFace(const ConePlaneSet& set, const Eigen::Vector3d& centre, int plane,
                  const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                  LineStretch* range) {
  const ConePlane& face = set.Plane(plane);
  const Eigen::Vector3d& normal = set.Normal(plane);
  const Eigen::Vector3d rp = set.Ray(face.view, face.p), rq = set.Ray(face.view, face.q);
  const Eigen::Vector3d offset = origin - centre;
  // Inside the wedge: (rp x X) . n >= 0 and (X x rq) . n >= 0 for X = offset + t direction.
  const std::array<std::array<double, 2>, 2> bounds = {
      {{rp.cross(offset).dot(normal), rp.cross(direction).dot(normal)},
       {offset.cross(rq).dot(normal), direction.cross(rq).dot(normal)}}};
  const std::array<int, 2> labels = {face.prev, face.next};
  for (int k = 0; k < 2; ++k) {
    const auto [f0, f1] = bounds[static_cast<size_t>(k)];
    if (!(f1 < 0.0)) continue;
    const double t = std::max(0.0, -f0 / f1);
    if (t < range->hi) {
      range->hi = t;
      range->hi_plane = labels[static_cast<size_t>(k)];
    }
  }
}

// The position of a plane pair among a vertex's three (sorted) planes: 0 for the first two,
// 1 for the first and last, 2 for the last two.
int PairSlot(const PlaneTriple& planes, int a, int b) {
  if (a == planes[0] && b == planes[1]) return 0;
  if (a == planes[0] && b == planes[2]) return 1;
  return 2;
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
    const int a = std::min(previous, edge.plane), b = std::max(previous, edge.plane);
    MarkDone(from, a, b);
    MarkDone(to, a, b);
    graph_.edges.push_back({a, b, from, to});
    ++graph_.viewing_edges;
  }

  // Traces the edges that leave every vertex found, until no vertex is new.
  HullEdgeGraph Finish() {
    for (size_t v = 0; v < graph_.vertices.size(); ++v) {
      const PlaneTriple planes = graph_.vertices[v].planes;
      for (const auto& [a, b, c] : {PlaneTriple{planes[0], planes[1], planes[2]},
                                    PlaneTriple{planes[0], planes[2], planes[1]},
                                    PlaneTriple{planes[1], planes[2], planes[0]}}) {
        if (set_.Plane(a).view == set_.Plane(b).view) continue;
        if (done_[v] & (1u << PairSlot(planes, a, b))) continue;
        TraceEdge(static_cast<int>(v), a, b, c);
      }
    }
    return std::move(graph_);
  }

 private:
  // The vertex on planes a, b, c at `position` (found before or added now); -1 for an end the
  // bounds box cut (c = -1).
  int End(int a, int b, int c, const Eigen::Vector3d& position) {
    if (c < 0) {
      ++graph_.open_ends;
      return -1;
    }
    const PlaneTriple key = SortedPlanes(a, b, c);
    const auto [it, added] = vertex_.try_emplace(key, static_cast<int>(graph_.vertices.size()));
    if (added) {
      graph_.vertices.push_back({key, position});
      done_.push_back(0);
    }
    return it->second;
  }

  void MarkDone(int vertex, int a, int b) {
    done_[static_cast<size_t>(vertex)] |=
        static_cast<uint8_t>(1u << PairSlot(graph_.vertices[static_cast<size_t>(vertex)].planes,
                                            std::min(a, b), std::max(a, b)));
  }

  // The edge that leaves vertex `from` (on planes a < b and c) along the line of planes a and
  // b, on the side that plane c keeps, up to the next vertex.
  void TraceEdge(int from, int a, int b, int c) {
    ++graph_.traced;
    MarkDone(from, a, b);
    const int view_a = set_.Plane(a).view, view_b = set_.Plane(b).view;
    Eigen::Vector3d direction = set_.Normal(a).cross(set_.Normal(b));
    if (!(direction.squaredNorm() > 0.0)) return;
    const int c_view = set_.Plane(c).view;
    const double rate = IntoFaceSide(set_, c_view == view_b ? b : a, c).dot(direction);
    if (rate < 0.0) direction = -direction;
    const Eigen::Vector3d origin = graph_.vertices[static_cast<size_t>(from)].position;
    const ConeLine line{view_a, origin, direction};
    LineStretch range{0.0, std::numeric_limits<double>::infinity(), c, -1};
    NarrowToFace(set_, centres_[static_cast<size_t>(view_a)], a, origin, direction, &range);
    NarrowToFace(set_, centres_[static_cast<size_t>(view_b)], b, origin, direction, &range);
    const std::optional<LineStretch> boxed = ClipToBox(line, bounds_, range);
    if (!boxed) return;
    const LineStretch edge = FirstExit(set_, centres_, line, *boxed, view_a, view_b, c, &buffers_);
    const int to = End(a, b, edge.hi_plane, origin + edge.hi * direction);
    if (to < 0) return;
    MarkDone(to, a, b);
    graph_.edges.push_back({a, b, from, to});
  }

  const ConePlaneSet& set_;
  const WorldBox& bounds_;
  std::vector<Eigen::Vector3d> centres_;
  HullEdgeGraph graph_;
  absl::flat_hash_map<PlaneTriple, int> vertex_;
  std::vector<uint8_t> done_;  // per vertex, the plane pairs whose edge is known (PairSlot bits)
  ConeLineBuffers buffers_;
};

}  // namespace

PlaneTriple SortedPlanes(int a, int b, int c) {
  PlaneTriple t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

Eigen::Vector3d IntoFaceSide(const ConePlaneSet& set, int face, int bound) {
  const ConePlane& plane = set.Plane(face);
  const Eigen::Vector3d& normal = set.Normal(face);
  if (bound == plane.prev) return normal.cross(set.Ray(plane.view, plane.p));
  if (bound == plane.next) return set.Ray(plane.view, plane.q).cross(normal);
  const Eigen::Vector3d& g = set.Normal(bound);
  return g - g.dot(normal) / normal.squaredNorm() * normal;
}

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

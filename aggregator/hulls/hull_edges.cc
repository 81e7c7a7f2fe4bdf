#include "aggregator/hulls/hull_edges.h"

#include <absl/container/flat_hash_map.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <utility>

#include "aggregator/hulls/cone_line_stretches.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Where the line origin + t direction (t >= 0) leaves plane `plane`'s face through the rays
// of its contour points: range.hi narrowed, `hi_plane` the plane beyond that ray.
void NarrowToFace(const ConePlaneSet& set, const Eigen::Vector3d& centre, int plane,
                  const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                  LineStretch* range) {
  const ConePlane& face = set.Plane(plane);
  const Eigen::Vector3d& normal = set.Normal(plane);
  const Eigen::Vector3d& rp = set.RayThroughP(plane);
  const Eigen::Vector3d& rq = set.RayThroughP(face.next);
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

// Edges traced per chunk of a round's tasks on one thread.
constexpr size_t kTasksPerChunk = 256;

// An edge to trace: from vertex `from` along the line of planes a < b, away from plane c:
// along `line` (normal a x normal b) if `forward`, else against it.
struct TraceTask {
  int from = -1, a = -1, b = -1, c = -1;
  Eigen::Vector3d line = Eigen::Vector3d::Zero();
  bool forward = true;

  Eigen::Vector3d Direction() const { return forward ? line : Eigen::Vector3d(-line); }
};

// Where a traced edge ends: on `plane` (-1 where the bounds box cut it) at `position`.
struct EdgeEnd {
  int plane = -1;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

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
    const Eigen::Vector3d& direction = set_.RayThroughP(edge.plane);
    const int from = End(previous, edge.plane, edge.near_plane, centre + edge.near * direction);
    const int to = End(previous, edge.plane, edge.far_plane, centre + edge.far * direction);
    if (from < 0 || to < 0) return;
    const int a = std::min(previous, edge.plane), b = std::max(previous, edge.plane);
    MarkDone(from, a, b);
    MarkDone(to, a, b);
    graph_.edges.push_back({a, b, from, to});
    ++graph_.viewing_edges;
  }

  // Traces the edges that leave every vertex found, until no vertex is new: in rounds, each
  // tracing the edges not yet known at the vertices the previous round found (and those it
  // put off), on `threads` threads, and adding their ends in a fixed order (so the graph does
  // not depend on the number of threads). Of two edges of a round on one line that face each
  // other (likely one edge seen from both ends) the second waits for the next round, which
  // drops it if the first ended at its vertex; any other edge traced from both ends in one
  // round is kept once.
  HullEdgeGraph Finish(int threads) {
    std::vector<TraceTask> tasks, put_off;
    std::vector<std::optional<EdgeEnd>> ends;
    std::vector<ConeLineBuffers> buffers;  // per chunk of a round, kept for their room
    for (size_t round_start = 0; round_start < graph_.vertices.size() || !put_off.empty();) {
      const size_t round_end = graph_.vertices.size();
      tasks.clear();
      for (const TraceTask& task : put_off)
        if (!Done(task)) tasks.push_back(task);
      for (size_t v = round_start; v < round_end; ++v) {
        const PlaneTriple planes = graph_.vertices[v].planes;
        for (const auto& [a, b, c] : {PlaneTriple{planes[0], planes[1], planes[2]},
                                      PlaneTriple{planes[0], planes[2], planes[1]},
                                      PlaneTriple{planes[1], planes[2], planes[0]}}) {
          TraceTask task{static_cast<int>(v), a, b, c};
          if (set_.Plane(a).view == set_.Plane(b).view || Done(task)) continue;
          task.line = set_.Normal(a).cross(set_.Normal(b));
          const int face = set_.Plane(c).view == set_.Plane(b).view ? b : a;
          task.forward = !(IntoFaceSide(set_, face, c).dot(task.line) < 0.0);
          tasks.push_back(task);
        }
      }
      round_start = round_end;
      PutOffFacingPairs(&tasks, &put_off);
      ends.assign(tasks.size(), std::nullopt);
      const size_t chunks = (tasks.size() + kTasksPerChunk - 1) / kTasksPerChunk;
      if (buffers.size() < chunks) buffers.resize(chunks);
      ParallelFor(chunks, tasks.size() >= kTasksPerChunk ? threads : 1, [&](size_t k) {
        for (size_t t = k * kTasksPerChunk; t < std::min(tasks.size(), (k + 1) * kTasksPerChunk);
             ++t)
          ends[t] = TraceEdge(tasks[t], &buffers[k]);
      });
      for (size_t t = 0; t < tasks.size(); ++t) {
        if (Done(tasks[t])) continue;  // traced from its other end earlier in this round
        const TraceTask& task = tasks[t];
        ++graph_.traced;
        MarkDone(task.from, task.a, task.b);
        if (!ends[t]) continue;
        const int to = End(task.a, task.b, ends[t]->plane, ends[t]->position);
        if (to < 0) continue;
        MarkDone(to, task.a, task.b);
        graph_.edges.push_back({task.a, task.b, task.from, to});
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

  // True if the edge of `task` is known.
  bool Done(const TraceTask& task) const {
    const auto from = static_cast<size_t>(task.from);
    return done_[from] & (1u << PairSlot(graph_.vertices[from].planes, task.a, task.b));
  }

  // Moves to `put_off` the second task of each two on one line that are next to each other
  // along it and face each other; the others keep their order.
  void PutOffFacingPairs(std::vector<TraceTask>* tasks, std::vector<TraceTask>* put_off) const {
    put_off->clear();
    // The tasks by line: counted out by their first plane (in task order), then each plane's
    // few tasks ordered by their second. Only the runs of one line matter, not their order.
    const size_t planes = set_.Planes().size();
    std::vector<uint32_t> first(planes + 1, 0);
    for (const TraceTask& task : *tasks)
      ++first[static_cast<size_t>(task.a) + 1];
    std::partial_sum(first.begin(), first.end(), first.begin());
    std::vector<uint32_t> by_line(tasks->size());
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (size_t t = 0; t < tasks->size(); ++t)
      by_line[fill[static_cast<size_t>((*tasks)[t].a)]++] = static_cast<uint32_t>(t);
    const auto second_plane = [&](uint32_t x, uint32_t y) {
      const int bx = (*tasks)[x].b, by = (*tasks)[y].b;
      return bx != by ? bx < by : x < y;
    };
    for (size_t a = 0; a < planes; ++a) {
      if (first[a + 1] - first[a] > 1)
        std::sort(by_line.begin() + first[a], by_line.begin() + first[a + 1], second_plane);
    }
    const auto same_line = [&](uint32_t x, uint32_t y) {
      return (*tasks)[x].a == (*tasks)[y].a && (*tasks)[x].b == (*tasks)[y].b;
    };
    struct Place {
      double along = 0;
      size_t task = 0;
    };
    std::vector<Place> run;
    std::vector<bool> later(tasks->size(), false);
    for (size_t begin = 0, end = 0; begin < by_line.size(); begin = end) {
      for (end = begin + 1; end < by_line.size() && same_line(by_line[begin], by_line[end]);)
        ++end;
      if (end - begin < 2) continue;
      run.clear();
      for (size_t k = begin; k < end; ++k) {
        const size_t t = by_line[k];
        const TraceTask& task = (*tasks)[t];
        run.push_back({task.line.dot(graph_.vertices[static_cast<size_t>(task.from)].position), t});
      }
      std::sort(run.begin(), run.end(), [](const Place& x, const Place& y) {
        return x.along != y.along ? x.along < y.along : x.task < y.task;
      });
      for (size_t k = 1; k < run.size(); ++k) {
        const size_t before = run[k - 1].task, after = run[k].task;
        if ((*tasks)[before].forward && !(*tasks)[after].forward && !later[before])
          later[after] = true;
      }
    }
    size_t kept = 0;
    for (size_t t = 0; t < tasks->size(); ++t) {
      if (later[t]) {
        put_off->push_back((*tasks)[t]);
      } else {
        (*tasks)[kept++] = (*tasks)[t];
      }
    }
    tasks->resize(kept);
  }

  void MarkDone(int vertex, int a, int b) {
    done_[static_cast<size_t>(vertex)] |=
        static_cast<uint8_t>(1u << PairSlot(graph_.vertices[static_cast<size_t>(vertex)].planes,
                                            std::min(a, b), std::max(a, b)));
  }

  // The edge that leaves vertex `task.from` (on planes a < b and c) along the line of planes
  // a and b, on the side that plane c keeps: where it ends (plane -1 where the bounds box cuts
  // it), nullopt where the line is degenerate or outside the box. Reads the graph only.
  std::optional<EdgeEnd> TraceEdge(const TraceTask& task, ConeLineBuffers* buffers) const {
    const int from = task.from, a = task.a, b = task.b, c = task.c;
    const int view_a = set_.Plane(a).view, view_b = set_.Plane(b).view;
    const Eigen::Vector3d direction = task.Direction();
    if (!(direction.squaredNorm() > 0.0)) return std::nullopt;
    const Eigen::Vector3d origin = graph_.vertices[static_cast<size_t>(from)].position;
    const ConeLine line{view_a, origin, direction};
    LineStretch range{0.0, std::numeric_limits<double>::infinity(), c, -1};
    NarrowToFace(set_, centres_[static_cast<size_t>(view_a)], a, origin, direction, &range);
    NarrowToFace(set_, centres_[static_cast<size_t>(view_b)], b, origin, direction, &range);
    const std::optional<LineStretch> boxed = ClipToBox(line, bounds_, range);
    if (!boxed) return std::nullopt;
    const LineStretch edge = FirstExit(set_, centres_, line, *boxed, view_a, view_b, c, buffers);
    return EdgeEnd{edge.hi_plane, origin + edge.hi * direction};
  }

  const ConePlaneSet& set_;
  const WorldBox& bounds_;
  std::vector<Eigen::Vector3d> centres_;
  HullEdgeGraph graph_;
  absl::flat_hash_map<PlaneTriple, int> vertex_;
  std::vector<uint8_t> done_;  // per vertex, the plane pairs whose edge is known (PairSlot bits)
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
  if (bound == plane.prev) return normal.cross(set.RayThroughP(face));
  if (bound == plane.next) return set.RayThroughP(plane.next).cross(normal);
  const Eigen::Vector3d& g = set.Normal(bound);
  return g - g.dot(normal) / normal.squaredNorm() * normal;
}

HullEdgeGraph TraceHullEdges(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                             const WorldBox& bounds, const std::vector<ViewingEdge>& viewing_edges,
                             int threads) {
  SILNET_CHECK(cameras.size() == set.Views());
  EdgeTracer tracer(cameras, set, bounds);
  for (const ViewingEdge& edge : viewing_edges)
    tracer.AddViewingEdge(edge);
  return tracer.Finish(threads);
}

}  // namespace silnet::aggregator

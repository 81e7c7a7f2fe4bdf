#include "aggregator/hulls/traced_hull_mesh.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "aggregator/hulls/loop_triangulation.h"

namespace silnet::aggregator {
namespace {

// An edge of one face, from vertex `from` to `to` with the face on its left (seen from outside
// the hull).
struct FaceEdge {
  int from = -1, to = -1;
};

// `edge` as an edge of face `face` (the other face on it `other`), directed so that the face
// lies on its left seen from outside (along -normal: the hull lies on the positive side of its
// cone planes).
FaceEdge Directed(const ConePlaneSet& set, const HullEdgeGraph& graph, int face, int other,
                  const HullEdge& edge) {
  const Eigen::Vector3d along = graph.vertices[static_cast<size_t>(edge.to)].position -
                                graph.vertices[static_cast<size_t>(edge.from)].position;
  const Eigen::Vector3d outward = -set.Normal(face);
  // Left of `along` seen from outside: outward x along.
  const bool forward = outward.cross(along).dot(IntoFaceSide(set, face, other)) > 0.0;
  return forward ? FaceEdge{edge.from, edge.to} : FaceEdge{edge.to, edge.from};
}

// Every face's directed edges in the graph's edge order: face f's are
// edges[starts[f], starts[f + 1]).
struct EdgesByFace {
  std::vector<uint32_t> starts;
  std::vector<FaceEdge> edges;
};

EdgesByFace SortEdgesByFace(const ConePlaneSet& set, const HullEdgeGraph& graph) {
  EdgesByFace by_face;
  by_face.starts.assign(set.Planes().size() + 1, 0);
  for (const HullEdge& edge : graph.edges) {
    ++by_face.starts[static_cast<size_t>(edge.a) + 1];
    ++by_face.starts[static_cast<size_t>(edge.b) + 1];
  }
  for (size_t f = 1; f < by_face.starts.size(); ++f)
    by_face.starts[f] += by_face.starts[f - 1];
  by_face.edges.resize(by_face.starts.back());
  std::vector<uint32_t> fill(by_face.starts.begin(), by_face.starts.end() - 1);
  for (const HullEdge& edge : graph.edges) {
    by_face.edges[fill[static_cast<size_t>(edge.a)]++] = Directed(set, graph, edge.a, edge.b, edge);
    by_face.edges[fill[static_cast<size_t>(edge.b)]++] = Directed(set, graph, edge.b, edge.a, edge);
  }
  return by_face;
}

}  // namespace

TracedHullMesh AssembleTracedHull(const ConePlaneSet& set, const HullEdgeGraph& graph) {
  TracedHullMesh result;
  const EdgesByFace by_face = SortEdgesByFace(set, graph);
  result.mesh.vertices.reserve(graph.vertices.size());
  result.mesh.triangles.reserve(2 * graph.vertices.size());  // Euler: a sphere's count
  for (const HullEdgeVertex& v : graph.vertices)
    result.mesh.vertices.push_back(v.position.cast<float>());
  std::vector<int> next(graph.vertices.size(), -1);
  // Reused from face to face: the face's loops in its chart (their inner vectors keep their
  // room) and their vertices one loop after another, as the triangulation numbers them.
  std::vector<std::vector<Eigen::Vector2d>> chart_loops;
  std::vector<int> flat;
  for (size_t f = 0; f + 1 < by_face.starts.size(); ++f) {
    const std::span<const FaceEdge> edges(by_face.edges.data() + by_face.starts[f],
                                          by_face.starts[f + 1] - by_face.starts[f]);
    if (edges.empty()) continue;
    ++result.faces;
    for (const FaceEdge& e : edges) {
      if (next[static_cast<size_t>(e.from)] >= 0) {
        result.reason = fmt::format("face {}: two edges leave vertex {}", f, e.from);
        return result;
      }
      next[static_cast<size_t>(e.from)] = e.to;
    }
    // The face's chart: a right-handed basis seen from outside.
    const Eigen::Vector3d outward = -set.Normal(static_cast<int>(f)).normalized();
    const Eigen::Vector3d u = outward.unitOrthogonal(), w = outward.cross(u);
    size_t used = 0;
    flat.clear();
    for (const FaceEdge& e : edges) {
      if (next[static_cast<size_t>(e.from)] < 0) continue;  // already in a loop
      if (chart_loops.size() == used) chart_loops.emplace_back();
      std::vector<Eigen::Vector2d>& chart = chart_loops[used++];
      chart.clear();
      int v = e.from;
      while (next[static_cast<size_t>(v)] >= 0) {
        flat.push_back(v);
        const Eigen::Vector3d& x = graph.vertices[static_cast<size_t>(v)].position;
        chart.emplace_back(x.dot(u), x.dot(w));
        const int to = next[static_cast<size_t>(v)];
        next[static_cast<size_t>(v)] = -1;
        v = to;
      }
      if (chart.size() < 3 || v != e.from) {
        result.reason = fmt::format("face {}: its edges do not close into loops", f);
        return result;
      }
    }
    chart_loops.resize(used);
    result.loops += used;
    const LoopTriangulation triangulation = TriangulateLoops(chart_loops);
    if (!triangulation.success) {
      result.reason = fmt::format("face {}: {}", f, triangulation.reason);
      return result;
    }
    for (const std::array<int, 3>& t : triangulation.triangles) {
      result.mesh.triangles.push_back({flat[static_cast<size_t>(t[0])],
                                       flat[static_cast<size_t>(t[1])],
                                       flat[static_cast<size_t>(t[2])]});
    }
  }
  result.success = true;
  return result;
}

}  // namespace silnet::aggregator

#include "aggregator/hulls/traced_hull_mesh.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <vector>

#include "aggregator/hulls/loop_triangulation.h"

namespace silnet::aggregator {
namespace {

// An edge of one face, from vertex `from` to `to` with the face on its left (seen from outside
// the hull).
struct FaceEdge {
  int from = -1, to = -1;
};

// Appends `edge` to face `face`'s list, directed so that the face lies on its left seen from
// outside (along -normal: the hull lies on the positive side of its cone planes).
void AddDirected(const ConePlaneSet& set, const HullEdgeGraph& graph, int face, int other,
                 const HullEdge& edge, std::vector<FaceEdge>* edges) {
  const Eigen::Vector3d along = graph.vertices[static_cast<size_t>(edge.to)].position -
                                graph.vertices[static_cast<size_t>(edge.from)].position;
  const Eigen::Vector3d outward = -set.Normal(face);
  // Left of `along` seen from outside: outward x along.
  const bool forward = outward.cross(along).dot(IntoFaceSide(set, face, other)) > 0.0;
  edges->push_back(forward ? FaceEdge{edge.from, edge.to} : FaceEdge{edge.to, edge.from});
}

}  // namespace

TracedHullMesh AssembleTracedHull(const ConePlaneSet& set, const HullEdgeGraph& graph) {
  TracedHullMesh result;
  std::vector<std::vector<FaceEdge>> face_edges(set.Planes().size());
  for (const HullEdge& edge : graph.edges) {
    AddDirected(set, graph, edge.a, edge.b, edge, &face_edges[static_cast<size_t>(edge.a)]);
    AddDirected(set, graph, edge.b, edge.a, edge, &face_edges[static_cast<size_t>(edge.b)]);
  }
  for (const HullEdgeVertex& v : graph.vertices)
    result.mesh.vertices.push_back(v.position.cast<float>());
  std::vector<int> next(graph.vertices.size(), -1);
  std::vector<std::vector<int>> loops;
  std::vector<std::vector<Eigen::Vector2d>> chart_loops;
  for (size_t f = 0; f < face_edges.size(); ++f) {
    const std::vector<FaceEdge>& edges = face_edges[f];
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
    loops.clear();
    chart_loops.clear();
    for (const FaceEdge& e : edges) {
      if (next[static_cast<size_t>(e.from)] < 0) continue;  // already in a loop
      std::vector<int>& loop = loops.emplace_back();
      std::vector<Eigen::Vector2d>& chart = chart_loops.emplace_back();
      int v = e.from;
      while (next[static_cast<size_t>(v)] >= 0) {
        loop.push_back(v);
        const Eigen::Vector3d& x = graph.vertices[static_cast<size_t>(v)].position;
        chart.emplace_back(x.dot(u), x.dot(w));
        const int to = next[static_cast<size_t>(v)];
        next[static_cast<size_t>(v)] = -1;
        v = to;
      }
      if (loop.size() < 3 || v != e.from) {
        result.reason = fmt::format("face {}: its edges do not close into loops", f);
        return result;
      }
    }
    result.loops += loops.size();
    const LoopTriangulation triangulation = TriangulateLoops(chart_loops);
    if (!triangulation.success) {
      result.reason = fmt::format("face {}: {}", f, triangulation.reason);
      return result;
    }
    std::vector<int> flat;
    for (const std::vector<int>& loop : loops)
      flat.insert(flat.end(), loop.begin(), loop.end());
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

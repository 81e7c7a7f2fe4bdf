#include "aggregator/stereo/hull_view_edges.h"

#include <algorithm>
#include <iterator>

#include "shared/util/disjoint_sets.h"

namespace silnet::aggregator {
namespace {

// The planes both sorted lists hold.
std::vector<int> Common(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> both;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
  return both;
}

// The ray a mesh edge lies on: the face of `view`'s contour edge ending at the ray's vertex,
// if the edge's shared planes hold two consecutive faces of one view; otherwise -1.
int RayOfEdge(const std::vector<int>& shared, const std::vector<ConePlane>& planes) {
  for (const int a : shared) {
    const int next = planes[static_cast<size_t>(a)].next;
    if (next >= 0 && std::binary_search(shared.begin(), shared.end(), next)) return a;
  }
  return -1;
}

}  // namespace

uint64_t MeshEdgeKey(int a, int b) {
  const auto lo = static_cast<uint32_t>(std::min(a, b));
  const auto hi = static_cast<uint32_t>(std::max(a, b));
  return (static_cast<uint64_t>(hi) << 32) | lo;
}

HullViewEdges FindHullViewEdges(const TriangleMesh& hull, const HullProvenance& provenance,
                                const std::vector<Eigen::Vector3d>& centres) {
  HullViewEdges edges;
  const std::vector<ConePlane>& planes = provenance.planes;
  const std::vector<std::vector<int>>& vertex_planes = provenance.vertex_planes;
  const size_t triangles = hull.triangles.size();
  edges.triangle_plane.assign(triangles, -1);
  for (size_t t = 0; t < triangles; ++t) {
    const auto& tri = hull.triangles[t];
    const std::vector<int> shared = Common(Common(vertex_planes[static_cast<size_t>(tri[0])],
                                                  vertex_planes[static_cast<size_t>(tri[1])]),
                                           vertex_planes[static_cast<size_t>(tri[2])]);
    if (!shared.empty()) edges.triangle_plane[t] = shared.front();
    for (size_t k = 0; k < 3; ++k) {
      auto [it, added] = edges.edge_triangles.try_emplace(MeshEdgeKey(tri[k], tri[(k + 1) % 3]),
                                                          std::array<int, 2>{-1, -1});
      it->second[it->second[0] < 0 ? 0 : 1] = static_cast<int>(t);
    }
  }
  // Pieces: the triangles of one cone face joined across their shared edges.
  DisjointSets pieces(triangles);
  for (const auto& [key, pair] : edges.edge_triangles) {
    const int plane = edges.triangle_plane[static_cast<size_t>(pair[0])];
    if (pair[1] >= 0 && plane >= 0 && plane == edges.triangle_plane[static_cast<size_t>(pair[1])])
      pieces.Union(static_cast<size_t>(pair[0]), static_cast<size_t>(pair[1]));
  }
  edges.triangle_piece.assign(triangles, -1);
  std::unordered_map<size_t, int> piece_number;
  for (size_t t = 0; t < triangles; ++t) {
    if (edges.triangle_plane[t] < 0) continue;
    const auto [it, added] =
        piece_number.try_emplace(pieces.Find(t), static_cast<int>(piece_number.size()));
    edges.triangle_piece[t] = it->second;
  }

  // Viewing edges, then the chains they form on each ray.
  std::unordered_map<int, std::vector<std::array<int, 2>>> ray_edges;
  for (const auto& [key, pair] : edges.edge_triangles) {
    const int a = static_cast<int>(key & 0xffffffffu), b = static_cast<int>(key >> 32);
    const int ray = RayOfEdge(
        Common(vertex_planes[static_cast<size_t>(a)], vertex_planes[static_cast<size_t>(b)]),
        planes);
    if (ray >= 0) ray_edges[ray].push_back({a, b});
  }
  for (auto& [ray, list] : ray_edges) {
    const int view = planes[static_cast<size_t>(ray)].view;
    const Eigen::Vector3d& centre = centres[static_cast<size_t>(view)];
    // The chains along the ray: edges joined through shared vertices.
    std::unordered_map<int, int> slot;
    for (const auto& e : list) {
      slot.try_emplace(e[0], static_cast<int>(slot.size()));
      slot.try_emplace(e[1], static_cast<int>(slot.size()));
    }
    DisjointSets chains(slot.size());
    for (const auto& e : list)
      chains.Union(static_cast<size_t>(slot[e[0]]), static_cast<size_t>(slot[e[1]]));
    std::unordered_map<size_t, size_t> segment_of_chain;
    const size_t first = edges.segments.size();
    const auto distance = [&](int v) {
      return (hull.vertices[static_cast<size_t>(v)].cast<double>() - centre).norm();
    };
    for (const auto& e : list) {
      const size_t chain = chains.Find(static_cast<size_t>(slot[e[0]]));
      const auto [it, added] = segment_of_chain.try_emplace(chain, edges.segments.size());
      if (added) {
        ViewEdgeSegment segment;
        segment.view = view;
        segment.ray = ray;
        segment.near_vertex = segment.far_vertex = e[0];
        edges.segments.push_back(segment);
      }
      ViewEdgeSegment& segment = edges.segments[it->second];
      segment.edges.push_back(MeshEdgeKey(e[0], e[1]));
      for (const int v : e) {
        if (distance(v) < distance(segment.near_vertex)) segment.near_vertex = v;
        if (distance(v) > distance(segment.far_vertex)) segment.far_vertex = v;
      }
      for (const int t : edges.edge_triangles[MeshEdgeKey(e[0], e[1])]) {
        if (t >= 0 && edges.triangle_piece[static_cast<size_t>(t)] >= 0)
          segment.pieces.push_back(edges.triangle_piece[static_cast<size_t>(t)]);
      }
    }
    for (size_t s = first; s < edges.segments.size(); ++s) {
      std::vector<int>& p = edges.segments[s].pieces;
      std::sort(p.begin(), p.end());
      p.erase(std::unique(p.begin(), p.end()), p.end());
    }
  }
  std::sort(edges.segments.begin(), edges.segments.end(),
            [&](const ViewEdgeSegment& x, const ViewEdgeSegment& y) {
              if (x.view != y.view) return x.view < y.view;
              if (x.ray != y.ray) return x.ray < y.ray;
              const Eigen::Vector3d& c = centres[static_cast<size_t>(x.view)];
              return (hull.vertices[static_cast<size_t>(x.near_vertex)].cast<double>() - c).norm() <
                     (hull.vertices[static_cast<size_t>(y.near_vertex)].cast<double>() - c).norm();
            });
  return edges;
}

}  // namespace silnet::aggregator

#include "aggregator/hulls/mesh_topology.h"

#include <algorithm>
#include <cstdint>
#include <utility>

#include "shared/util/disjoint_sets.h"

namespace silnet::aggregator {
std::vector<MeshComponent> MeshComponents(const TriangleMesh& mesh) {
  const size_t n = mesh.vertices.size();
  std::vector<std::array<int32_t, 3>> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const bool in_range = std::all_of(
        t.begin(), t.end(), [n](int32_t v) { return v >= 0 && static_cast<size_t>(v) < n; });
    if (in_range && t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) triangles.push_back(t);
  }
  DisjointSets sets(n);
  std::vector<uint8_t> used(n, 0);
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      used[static_cast<size_t>(t[k])] = 1;
      sets.Union(static_cast<size_t>(t[k]), static_cast<size_t>(t[(k + 1) % 3]));
    }
  }
  // Piece index per root, in order of first appearance.
  std::vector<int32_t> piece(n, -1);
  std::vector<MeshComponent> pieces;
  for (size_t v = 0; v < n; ++v) {
    if (!used[v]) continue;
    int32_t& p = piece[sets.Find(v)];
    if (p < 0) {
      p = static_cast<int32_t>(pieces.size());
      pieces.emplace_back();
    }
    ++pieces[static_cast<size_t>(p)].vertices;
  }
  std::vector<std::pair<uint64_t, int32_t>> edges;  // (undirected edge key, piece)
  edges.reserve(3 * triangles.size());
  for (const auto& t : triangles) {
    const int32_t p = piece[sets.Find(static_cast<size_t>(t[0]))];
    ++pieces[static_cast<size_t>(p)].triangles;
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<uint32_t>(std::min(t[k], t[(k + 1) % 3]));
      const auto b = static_cast<uint32_t>(std::max(t[k], t[(k + 1) % 3]));
      edges.emplace_back((static_cast<uint64_t>(a) << 32) | b, p);
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<long> edge_count(pieces.size(), 0);
  for (const auto& e : edges)
    ++edge_count[static_cast<size_t>(e.second)];
  for (size_t p = 0; p < pieces.size(); ++p) {
    MeshComponent& c = pieces[p];
    c.euler_characteristic =
        static_cast<long>(c.vertices) - edge_count[p] + static_cast<long>(c.triangles);
    c.genus = (2 - c.euler_characteristic) / 2;
  }
  std::stable_sort(
      pieces.begin(), pieces.end(),
      [](const MeshComponent& a, const MeshComponent& b) { return a.triangles > b.triangles; });
  return pieces;
}

}  // namespace silnet::aggregator

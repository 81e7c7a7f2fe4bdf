#include "aggregator/hulls/mesh_topology.h"

#include <algorithm>
#include <cstdint>
#include <utility>

#include "shared/util/disjoint_sets.h"

namespace silnet::aggregator {
namespace {

bool IsProperTriangle(const std::array<int32_t, 3>& t, size_t vertices) {
  const bool in_range = std::all_of(t.begin(), t.end(), [vertices](int32_t v) {
    return v >= 0 && static_cast<size_t>(v) < vertices;
  });
  return in_range && t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
}

}  // namespace

std::vector<int32_t> TrianglePieces(const TriangleMesh& mesh, size_t* pieces) {
  const size_t n = mesh.vertices.size();
  DisjointSets sets(n);
  for (const auto& t : mesh.triangles) {
    if (!IsProperTriangle(t, n)) continue;
    sets.Union(static_cast<size_t>(t[0]), static_cast<size_t>(t[1]));
    sets.Union(static_cast<size_t>(t[1]), static_cast<size_t>(t[2]));
  }
  // Each proper triangle's root first; a root is its set's smallest vertex, so numbering the
  // roots in vertex order numbers the pieces by their smallest vertex.
  std::vector<int32_t> piece(mesh.triangles.size(), -1);
  std::vector<int32_t> piece_of_root(n, -1);
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (!IsProperTriangle(mesh.triangles[i], n)) continue;
    const size_t root = sets.Find(static_cast<size_t>(mesh.triangles[i][0]));
    piece[i] = static_cast<int32_t>(root);
    piece_of_root[root] = 0;
  }
  int32_t count = 0;
  for (int32_t& p : piece_of_root)
    if (p == 0) p = ++count;
  for (int32_t& p : piece)
    if (p >= 0) p = piece_of_root[static_cast<size_t>(p)] - 1;
  if (pieces != nullptr) *pieces = static_cast<size_t>(count);
  return piece;
}

std::vector<MeshComponent> MeshComponents(const TriangleMesh& mesh) {
  size_t count = 0;
  const std::vector<int32_t> piece_of = TrianglePieces(mesh, &count);
  std::vector<MeshComponent> pieces(count);
  std::vector<uint8_t> counted(mesh.vertices.size(), 0);
  std::vector<std::pair<uint64_t, int32_t>> edges;  // (undirected edge key, piece)
  edges.reserve(3 * mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const int32_t p = piece_of[i];
    if (p < 0) continue;
    const auto& t = mesh.triangles[i];
    ++pieces[static_cast<size_t>(p)].triangles;
    for (int k = 0; k < 3; ++k) {
      if (counted[static_cast<size_t>(t[k])] == 0) {
        counted[static_cast<size_t>(t[k])] = 1;
        ++pieces[static_cast<size_t>(p)].vertices;
      }
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

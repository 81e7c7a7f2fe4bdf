#include "aggregator/hulls/mesh_check.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

namespace silnet::aggregator {

MeshCheck CheckClosedManifold(const TriangleMesh& mesh) {
  MeshCheck check;
  const auto num_vertices = static_cast<int64_t>(mesh.vertices.size());
  auto key = [](int64_t a, int64_t b) {
    return static_cast<uint64_t>(a) << 32 | static_cast<uint64_t>(b);
  };
  // Directed edge -> number of triangles that run along it.
  std::unordered_map<uint64_t, int> directed;
  directed.reserve(mesh.triangles.size() * 3);
  std::vector<uint8_t> referenced(mesh.vertices.size(), 0);
  for (const auto& t : mesh.triangles) {
    bool ok = t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    for (int32_t v : t)
      ok = ok && v >= 0 && v < num_vertices;
    if (!ok) {
      ++check.bad_indices;
      continue;
    }
    for (int e = 0; e < 3; ++e) {
      ++directed[key(t[static_cast<size_t>(e)], t[static_cast<size_t>((e + 1) % 3)])];
      referenced[static_cast<size_t>(t[static_cast<size_t>(e)])] = 1;
    }
  }
  size_t undirected_edges = 0;
  for (const auto& [k, count] : directed) {
    const int64_t a = static_cast<int64_t>(k >> 32), b = static_cast<int64_t>(k & 0xffffffffu);
    const auto reverse = directed.find(key(b, a));
    const int back = reverse == directed.end() ? 0 : reverse->second;
    if (a < b || back == 0) ++undirected_edges;
    if (a > b && back > 0) continue;  // counted from the other direction
    const int total = count + back;
    if (total == 1) {
      ++check.open_edges;
    } else if (total > 2) {
      ++check.non_manifold_edges;
    } else if (count != 1 || back != 1) {
      ++check.misoriented_edges;
    }
  }
  // Fans: around vertex v, triangle (v, a, b) links a -> b; one cycle per manifold vertex.
  std::vector<std::vector<std::pair<int32_t, int32_t>>> links(mesh.vertices.size());
  for (const auto& t : mesh.triangles) {
    bool ok = t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    for (int32_t v : t)
      ok = ok && v >= 0 && v < num_vertices;
    if (!ok) continue;
    for (size_t e = 0; e < 3; ++e)
      links[static_cast<size_t>(t[e])].emplace_back(t[(e + 1) % 3], t[(e + 2) % 3]);
  }
  for (const auto& link : links) {
    if (link.empty()) continue;
    std::map<int32_t, int32_t> next;
    for (const auto& [a, b] : link)
      next[a] = b;
    if (next.size() != link.size()) {
      ++check.non_manifold_vertices;
      continue;
    }
    // Walk from the first link; a single fan visits every link before returning.
    size_t steps = 0;
    int32_t at = link.front().first;
    do {
      const auto it = next.find(at);
      if (it == next.end()) break;
      at = it->second;
      ++steps;
    } while (at != link.front().first && steps <= link.size());
    if (steps != link.size() || at != link.front().first) ++check.non_manifold_vertices;
  }
  const auto used_vertices = static_cast<long>(std::count(referenced.begin(), referenced.end(), 1));
  check.euler_characteristic = used_vertices - static_cast<long>(undirected_edges) +
                               static_cast<long>(mesh.triangles.size() - check.bad_indices);
  if (check.bad_indices) {
    check.reason = "triangles with invalid vertex indices";
  } else if (check.open_edges) {
    check.reason = "open edges (used by one triangle)";
  } else if (check.non_manifold_edges) {
    check.reason = "edges shared by more than two triangles";
  } else if (check.misoriented_edges) {
    check.reason = "inconsistently oriented triangles";
  } else if (check.non_manifold_vertices) {
    check.reason = "vertices whose triangles form several fans";
  }
  check.closed_manifold = check.reason.empty();
  return check;
}

}  // namespace silnet::aggregator

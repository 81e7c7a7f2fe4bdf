#include "aggregator/hulls/mesh_check.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace silnet::aggregator {

namespace {

// True if the triangle's indices are distinct and in range.
bool ValidTriangle(const std::array<int32_t, 3>& t, int64_t num_vertices) {
  bool ok = t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
  for (int32_t v : t)
    ok = ok && v >= 0 && v < num_vertices;
  return ok;
}

// The number of links in `link` whose entry `member` is `vertex`.
int CountLinks(const std::pair<int32_t, int32_t>* link, size_t size, int32_t vertex,
               int32_t std::pair<int32_t, int32_t>::*member) {
  int count = 0;
  for (size_t k = 0; k < size; ++k)
    count += link[k].*member == vertex ? 1 : 0;
  return count;
}

// True if following a -> b from the first link visits every link once and comes back: the
// triangles around the vertex form one closed fan. The walk takes the first link leaving each
// vertex, so its next step depends on the vertex alone: back at its start for the first time,
// it has passed distinct vertices and so distinct links, all of them if it took as many steps
// as there are links; a walk caught in a cycle away from the start is cut off after that many.
bool IsSingleFan(const std::pair<int32_t, int32_t>* link, size_t size) {
  size_t steps = 0;
  int32_t at = link[0].first;
  do {
    size_t k = 0;
    while (k < size && link[k].first != at)
      ++k;
    if (k == size || ++steps > size) return false;
    at = link[k].second;
  } while (at != link[0].first);
  return steps == size;
}

}  // namespace

MeshCheck CheckClosedManifold(const TriangleMesh& mesh) {
  MeshCheck check;
  const auto num_vertices = static_cast<int64_t>(mesh.vertices.size());
  // Around vertex v, triangle (v, a, b) gives the link a -> b: edge v -> a leaves v, edge
  // b -> v enters it. Links are stored per vertex (offsets into one array).
  std::vector<uint32_t> offsets(mesh.vertices.size() + 1, 0);
  for (const auto& t : mesh.triangles) {
    if (!ValidTriangle(t, num_vertices)) {
      ++check.bad_indices;
      continue;
    }
    for (int32_t v : t)
      ++offsets[static_cast<size_t>(v) + 1];
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    offsets[v + 1] += offsets[v];
  std::vector<std::pair<int32_t, int32_t>> links(offsets.back());
  std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (const auto& t : mesh.triangles) {
    if (!ValidTriangle(t, num_vertices)) continue;
    for (size_t e = 0; e < 3; ++e)
      links[fill[static_cast<size_t>(t[e])]++] = {t[(e + 1) % 3], t[(e + 2) % 3]};
  }
  size_t undirected_edges = 0;
  long used_vertices = 0;
  std::vector<int32_t> neighbours;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const std::pair<int32_t, int32_t>* link = links.data() + offsets[v];
    const size_t size = offsets[v + 1] - offsets[v];
    if (size == 0) continue;
    ++used_vertices;
    // A single fan settles every edge at v: each neighbour is entered and left once.
    if (IsSingleFan(link, size)) {
      for (size_t k = 0; k < size; ++k)
        undirected_edges += link[k].first > static_cast<int32_t>(v) ? 1 : 0;
      continue;
    }
    ++check.non_manifold_vertices;
    // Otherwise each edge {v, u} is judged once, at its lower end, from v's own links.
    neighbours.clear();
    for (size_t k = 0; k < size; ++k) {
      for (int32_t u : {link[k].first, link[k].second}) {
        if (u > static_cast<int32_t>(v)) neighbours.push_back(u);
      }
    }
    std::sort(neighbours.begin(), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
    undirected_edges += neighbours.size();
    for (int32_t u : neighbours) {
      const int out = CountLinks(link, size, u, &std::pair<int32_t, int32_t>::first);
      const int back = CountLinks(link, size, u, &std::pair<int32_t, int32_t>::second);
      if (out + back == 1) {
        ++check.open_edges;
      } else if (out + back > 2) {
        ++check.non_manifold_edges;
      } else if (out != 1 || back != 1) {
        ++check.misoriented_edges;
      }
    }
  }
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

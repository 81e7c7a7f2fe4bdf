#include "aggregator/hulls/in_plane_gap_filler.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>

namespace silnet::aggregator {
namespace {

// Loops longer than this are not gaps between faces but a missing part of the surface.
constexpr size_t kLongestLoop = 64;

uint64_t DirectedEdge(int32_t from, int32_t to) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(from)) << 32) | static_cast<uint32_t>(to);
}

// Every triangle's directed edges, sorted.
std::vector<uint64_t> DirectedEdges(const TriangleMesh& mesh) {
  std::vector<uint64_t> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    for (size_t k = 0; k < 3; ++k)
      edges.push_back(DirectedEdge(t[k], t[(k + 1) % 3]));
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

bool HasEdge(const std::vector<uint64_t>& edges, int32_t from, int32_t to) {
  return std::binary_search(edges.begin(), edges.end(), DirectedEdge(from, to));
}

// True if the sorted lists `a`, `b` and `c` have a member in common.
bool ShareMember(const std::vector<int>& a, const std::vector<int>& b, const std::vector<int>& c) {
  return std::any_of(a.begin(), a.end(), [&](int x) {
    return std::binary_search(b.begin(), b.end(), x) && std::binary_search(c.begin(), c.end(), x);
  });
}

// The boundary's simple loops, each listed along its open edges. Where loops touch at a
// vertex (it leaves the boundary more than once), the walk leaves it for a vertex that shares
// a plane with the edge it came in on, and a walk that comes back to a vertex of its own
// path closes a loop there. False if the boundary is not a union of loops.
bool TraceBoundaryLoops(const std::vector<uint64_t>& edges,
                        const std::vector<std::vector<int>>& vertex_planes,
                        std::vector<std::vector<int32_t>>& loops) {
  std::unordered_map<int32_t, std::vector<int32_t>> out;
  for (const uint64_t edge : edges) {
    const auto from = static_cast<int32_t>(edge >> 32);
    const auto to = static_cast<int32_t>(edge & 0xFFFFFFFFu);
    if (!HasEdge(edges, to, from)) out[from].push_back(to);
  }
  const auto planes = [&](int32_t v) -> const std::vector<int>& {
    return vertex_planes[static_cast<size_t>(v)];
  };
  std::vector<int32_t> path;
  std::unordered_map<int32_t, size_t> position;  // of each vertex on `path`
  for (auto& [start, leaving_start] : out) {
    while (!leaving_start.empty()) {
      path.assign(1, start);
      position = {{start, 0}};
      for (;;) {
        const auto leaving = out.find(path.back());
        if (leaving == out.end() || leaving->second.empty()) {
          if (path.size() == 1) break;
          return false;  // the walk is stuck: more edges enter this vertex than leave it
        }
        std::vector<int32_t>& options = leaving->second;
        size_t pick = 0;
        for (size_t k = 0; path.size() > 1 && k < options.size(); ++k) {
          if (ShareMember(planes(path[path.size() - 2]), planes(path.back()), planes(options[k]))) {
            pick = k;
            break;
          }
        }
        const int32_t next = options[pick];
        options.erase(options.begin() + static_cast<std::ptrdiff_t>(pick));
        const auto seen = position.find(next);
        if (seen == position.end()) {
          position.emplace(next, path.size());
          path.push_back(next);
          continue;
        }
        const size_t first = seen->second;
        loops.emplace_back(path.begin() + static_cast<std::ptrdiff_t>(first), path.end());
        for (size_t k = first + 1; k < path.size(); ++k)
          position.erase(path[k]);
        path.resize(first + 1);
      }
    }
  }
  return true;
}

// True if every vertex of `loop` lies on some one plane.
bool SharePlane(const std::vector<std::vector<int>>& vertex_planes,
                const std::vector<int32_t>& loop) {
  std::vector<int> common = vertex_planes[static_cast<size_t>(loop.front())];
  std::vector<int> kept;
  for (const int32_t v : loop) {
    const std::vector<int>& planes = vertex_planes[static_cast<size_t>(v)];
    kept.clear();
    std::set_intersection(common.begin(), common.end(), planes.begin(), planes.end(),
                          std::back_inserter(kept));
    common.swap(kept);
  }
  return !common.empty();
}

// The least-area triangulation of polygon `polygon` (vertex indices of `mesh`) whose triangles
// run the polygon's way round, using no diagonal `edges` already holds; appended to the mesh.
// Returns its area, or -1 (nothing appended) if every triangulation needs such a diagonal.
double FillLeastArea(const std::vector<int32_t>& polygon, const std::vector<uint64_t>& edges,
                     TriangleMesh& mesh) {
  const size_t n = polygon.size();
  const auto point = [&](size_t k) -> Eigen::Vector3d {
    return mesh.vertices[static_cast<size_t>(polygon[k])].cast<double>();
  };
  const auto usable = [&](size_t i, size_t j) {
    if (j == i + 1 || (i == 0 && j == n - 1)) return true;  // a side of the polygon
    return !HasEdge(edges, polygon[i], polygon[j]) && !HasEdge(edges, polygon[j], polygon[i]);
  };
  constexpr double kNone = std::numeric_limits<double>::infinity();
  // cost[i][j]: least area of the sub-polygon i..j (j > i + 1) closed by the diagonal i-j.
  std::vector<double> cost(n * n, 0.0);
  std::vector<size_t> apex(n * n, 0);
  for (size_t length = 2; length < n; ++length) {
    for (size_t i = 0; i + length < n; ++i) {
      const size_t j = i + length;
      double best = kNone;
      if (usable(i, j)) {
        for (size_t k = i + 1; k < j; ++k) {
          const double area = 0.5 * (point(k) - point(i)).cross(point(j) - point(i)).norm();
          const double total = cost[i * n + k] + cost[k * n + j] + area;
          if (total < best) best = total, apex[i * n + j] = k;
        }
      }
      cost[i * n + j] = best;
    }
  }
  if (!(cost[n - 1] < kNone)) return -1;
  std::vector<std::pair<size_t, size_t>> pending = {{0, n - 1}};
  while (!pending.empty()) {
    const auto [i, j] = pending.back();
    pending.pop_back();
    if (j < i + 2) continue;
    const size_t k = apex[i * n + j];
    mesh.triangles.push_back({polygon[i], polygon[k], polygon[j]});
    pending.emplace_back(i, k);
    pending.emplace_back(k, j);
  }
  return cost[n - 1];
}

}  // namespace

GapFilling FillInPlaneGaps(const std::vector<std::vector<int>>& vertex_planes, TriangleMesh& mesh) {
  GapFilling filling;
  std::vector<uint64_t> edges = DirectedEdges(mesh);
  std::vector<std::vector<int32_t>> loops;
  if (!TraceBoundaryLoops(edges, vertex_planes, loops)) return filling;
  filling.loops = loops.size();
  for (std::vector<int32_t>& loop : loops) {
    if (loop.size() < 3 || loop.size() > kLongestLoop || !SharePlane(vertex_planes, loop)) continue;
    std::reverse(loop.begin(), loop.end());  // the filling runs against the open edges
    const size_t before = mesh.triangles.size();
    const double area = FillLeastArea(loop, edges, mesh);
    if (area < 0) continue;
    // The patch's edges count for the loops after it (none may use them as a diagonal again).
    for (size_t t = before; t < mesh.triangles.size(); ++t) {
      for (size_t k = 0; k < 3; ++k) {
        const uint64_t edge = DirectedEdge(mesh.triangles[t][k], mesh.triangles[t][(k + 1) % 3]);
        edges.insert(std::upper_bound(edges.begin(), edges.end(), edge), edge);
      }
    }
    ++filling.filled;
    filling.area += area;
    double perimeter = 0;
    for (size_t k = 0; k < loop.size(); ++k) {
      perimeter += (mesh.vertices[static_cast<size_t>(loop[k])] -
                    mesh.vertices[static_cast<size_t>(loop[(k + 1) % loop.size()])])
                       .cast<double>()
                       .norm();
    }
    filling.widest = std::max(filling.widest, 2 * area / perimeter);
  }
  return filling;
}

}  // namespace silnet::aggregator

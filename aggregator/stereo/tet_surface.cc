#include "aggregator/stereo/tet_surface.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <numeric>

#include "aggregator/stereo/taubin_smoothing.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// The face of `cell` opposite corner `opposite`, oriented away from the cell.
std::array<int32_t, 3> OutwardFace(const TetMesh& mesh, int32_t cell, int opposite) {
  const Tetrahedron& t = mesh.tetrahedra[static_cast<size_t>(cell)];
  std::array<int32_t, 3> f{};
  int k = 0;
  for (int c = 0; c < 4; ++c)
    if (c != opposite) f[k++] = t[c];
  const Eigen::Vector3d& a = mesh.vertices[f[0]];
  const Eigen::Vector3d normal = (mesh.vertices[f[1]] - a).cross(mesh.vertices[f[2]] - a);
  if (normal.dot(mesh.vertices[t[opposite]] - a) > 0) std::swap(f[1], f[2]);
  return f;
}

// The boundary faces (in mesh vertex ids, oriented outwards).
std::vector<std::array<int32_t, 3>> BoundaryFaces(const TetMesh& mesh,
                                                  const std::vector<CellFace>& faces,
                                                  const std::vector<uint8_t>& interior) {
  std::vector<std::array<int32_t, 3>> out;
  for (size_t k = 0; k < faces.size(); ++k) {
    const int32_t cell = faces[k].cell;
    if (!interior[static_cast<size_t>(cell)]) continue;
    if (k + 1 < faces.size() && faces[k].ids == faces[k + 1].ids &&
        interior[static_cast<size_t>(faces[k + 1].cell)])
      continue;
    if (k > 0 && faces[k].ids == faces[k - 1].ids &&
        interior[static_cast<size_t>(faces[k - 1].cell)])
      continue;
    out.push_back(OutwardFace(mesh, cell, faces[k].opposite));
  }
  return out;
}

// Root of x in a union-find forest with path halving.
int32_t Find(std::vector<int32_t>& parent, int32_t x) {
  while (parent[static_cast<size_t>(x)] != x) {
    parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    x = parent[static_cast<size_t>(x)];
  }
  return x;
}

// The boundary faces as a mesh of their own vertices; `remap` (if given) gets, per mesh
// vertex, its index in the result or -1.
TriangleMesh BoundaryMesh(const TetMesh& mesh, const std::vector<CellFace>& faces,
                          const std::vector<uint8_t>& interior, std::vector<int32_t>* remap) {
  SILNET_CHECK(interior.size() == mesh.tetrahedra.size());
  TriangleMesh surface;
  std::vector<int32_t> local;
  std::vector<int32_t>& ids = remap ? *remap : local;
  ids.assign(mesh.vertices.size(), -1);
  for (const auto& f : BoundaryFaces(mesh, faces, interior)) {
    std::array<int32_t, 3> triangle{};
    for (int k = 0; k < 3; ++k) {
      int32_t& id = ids[static_cast<size_t>(f[k])];
      if (id < 0) {
        id = static_cast<int32_t>(surface.vertices.size());
        surface.vertices.push_back(mesh.vertices[f[k]].cast<float>());
      }
      triangle[k] = id;
    }
    surface.triangles.push_back(triangle);
  }
  return surface;
}

}  // namespace

std::vector<CellFace> SortedCellFaces(const TetMesh& mesh) {
  std::vector<CellFace> faces;
  faces.reserve(4 * mesh.tetrahedra.size());
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    for (int o = 0; o < 4; ++o) {
      CellFace f;
      f.cell = static_cast<int32_t>(t);
      f.opposite = static_cast<int8_t>(o);
      int k = 0;
      for (int c = 0; c < 4; ++c)
        if (c != o) f.ids[k++] = mesh.tetrahedra[t][c];
      std::sort(f.ids.begin(), f.ids.end());
      faces.push_back(f);
    }
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

TriangleMesh InteriorBoundary(const TetMesh& mesh, const std::vector<CellFace>& faces,
                              const std::vector<uint8_t>& interior) {
  return BoundaryMesh(mesh, faces, interior, nullptr);
}

size_t RepairPinches(const TetMesh& mesh, const std::vector<CellFace>& faces,
                     std::vector<uint8_t>* interior, const std::vector<uint8_t>& avoid) {
  SILNET_CHECK(interior->size() == mesh.tetrahedra.size());
  SILNET_CHECK(avoid.empty() || avoid.size() == mesh.tetrahedra.size());
  // Cells around each vertex (CSR).
  const size_t vertices = mesh.vertices.size();
  std::vector<size_t> begin(vertices + 1, 0);
  for (const Tetrahedron& t : mesh.tetrahedra)
    for (int32_t v : t)
      ++begin[static_cast<size_t>(v) + 1];
  std::partial_sum(begin.begin(), begin.end(), begin.begin());
  std::vector<int32_t> cells(begin.back());
  {
    std::vector<size_t> next(begin.begin(), begin.end() - 1);
    for (size_t t = 0; t < mesh.tetrahedra.size(); ++t)
      for (int32_t v : mesh.tetrahedra[t])
        cells[next[static_cast<size_t>(v)]++] = static_cast<int32_t>(t);
  }
  size_t added = 0;
  std::vector<int32_t> parent;
  for (int round = 0; round < 100; ++round) {
    const auto boundary = BoundaryFaces(mesh, faces, *interior);
    // Each vertex's link: for its boundary faces, the edge between the other two corners.
    std::vector<std::array<int32_t, 3>> link;  // vertex, a, b
    link.reserve(3 * boundary.size());
    std::vector<std::pair<int64_t, int>> edges;
    edges.reserve(3 * boundary.size());
    for (const auto& f : boundary) {
      for (int k = 0; k < 3; ++k) {
        link.push_back({f[k], f[(k + 1) % 3], f[(k + 2) % 3]});
        const int32_t a = std::min(f[k], f[(k + 1) % 3]), b = std::max(f[k], f[(k + 1) % 3]);
        edges.emplace_back((static_cast<int64_t>(a) << 32) | static_cast<uint32_t>(b), 0);
      }
    }
    std::vector<int32_t> pinched;  // vertices to grow around
    std::vector<std::pair<int32_t, int32_t>> pinched_edges;
    std::sort(edges.begin(), edges.end());
    for (size_t k = 0; k < edges.size();) {
      size_t j = k;
      while (j < edges.size() && edges[j].first == edges[k].first)
        ++j;
      if (j - k > 2)
        pinched_edges.emplace_back(static_cast<int32_t>(edges[k].first >> 32),
                                   static_cast<int32_t>(edges[k].first & 0xffffffff));
      k = j;
    }
    std::sort(link.begin(), link.end());
    for (size_t k = 0; k < link.size();) {
      size_t j = k;
      while (j < link.size() && link[j][0] == link[k][0])
        ++j;
      // Components of the link graph over the neighbours (ids local to this vertex).
      std::vector<int32_t> ids;
      for (size_t i = k; i < j; ++i) {
        ids.push_back(link[i][1]);
        ids.push_back(link[i][2]);
      }
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      parent.resize(ids.size());
      std::iota(parent.begin(), parent.end(), 0);
      const auto local = [&](int32_t id) {
        return static_cast<int32_t>(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin());
      };
      size_t components = ids.size();
      for (size_t i = k; i < j; ++i) {
        const int32_t a = Find(parent, local(link[i][1])), b = Find(parent, local(link[i][2]));
        if (a != b) {
          parent[static_cast<size_t>(a)] = b;
          --components;
        }
      }
      if (components > 1) pinched.push_back(link[k][0]);
      k = j;
    }
    size_t grown = 0;
    // Cells to avoid only when nothing else is left to add.
    for (const bool allow_avoided : {false, true}) {
      const auto grow = [&](int32_t cell) {
        const auto c = static_cast<size_t>(cell);
        if ((*interior)[c] || (!allow_avoided && !avoid.empty() && avoid[c])) return;
        (*interior)[c] = 1;
        ++grown;
      };
      for (const auto& [a, b] : pinched_edges) {
        for (size_t i = begin[static_cast<size_t>(a)]; i < begin[static_cast<size_t>(a) + 1]; ++i) {
          const Tetrahedron& t = mesh.tetrahedra[static_cast<size_t>(cells[i])];
          if (std::find(t.begin(), t.end(), b) != t.end()) grow(cells[i]);
        }
      }
      for (int32_t v : pinched)
        for (size_t i = begin[static_cast<size_t>(v)]; i < begin[static_cast<size_t>(v) + 1]; ++i)
          grow(cells[i]);
      if (grown > 0) break;
    }
    added += grown;
    if (grown == 0) break;
  }
  return added;
}

TriangleMesh ExtractTetSurface(const TetMesh& mesh, const std::vector<CellFace>& faces,
                               std::vector<uint8_t> interior, const TetSurfaceOptions& options,
                               const std::vector<int32_t>& pinned,
                               const std::vector<uint8_t>& avoid, size_t* repaired) {
  const size_t grown = RepairPinches(mesh, faces, &interior, avoid);
  if (repaired) *repaired = grown;
  std::vector<int32_t> remap;  // mesh vertex -> surface vertex, to pin cell corners
  TriangleMesh surface = BoundaryMesh(mesh, faces, interior, &remap);
  const auto shift = static_cast<float>(options.max_vertex_shift);
  std::vector<Eigen::Vector3f> lo(surface.vertices.size()), hi(surface.vertices.size());
  for (size_t i = 0; i < surface.vertices.size(); ++i) {
    lo[i] = surface.vertices[i].array() - shift;
    hi[i] = surface.vertices[i].array() + shift;
  }
  for (int32_t cell : pinned) {
    for (int32_t v : mesh.tetrahedra[static_cast<size_t>(cell)]) {
      const int32_t id = remap[static_cast<size_t>(v)];
      if (id >= 0)
        lo[static_cast<size_t>(id)] = hi[static_cast<size_t>(id)] =
            surface.vertices[static_cast<size_t>(id)];
    }
  }
  TaubinSmooth(&surface, options.smoothing_iterations, options.smoothing_lambda,
               options.smoothing_mu, lo, hi);
  return surface;
}

}  // namespace silnet::aggregator

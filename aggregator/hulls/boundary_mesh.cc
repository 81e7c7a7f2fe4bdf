#include "aggregator/hulls/boundary_mesh.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "shared/util/disjoint_sets.h"

namespace silnet::aggregator {
namespace {

using Lattice = Eigen::Vector3i;

// Unit step along axis `axis` (0..2) with sign `sign` (+1 / -1).
Lattice Step(int axis, int sign) {
  Lattice s = Lattice::Zero();
  s[axis] = sign;
  return s;
}

// Direction index 0..5: axis = dir / 2, sign = + for even, - for odd.
int DirAxis(int dir) {
  return dir / 2;
}
int DirSign(int dir) {
  return dir % 2 == 0 ? 1 : -1;
}
int MakeDir(int axis, int sign) {
  return 2 * axis + (sign > 0 ? 0 : 1);
}

// One boundary square: voxel `voxel` and its outward side `dir`.
struct Face {
  Lattice voxel;
  int dir = 0;
  std::array<Lattice, 4> corners;  // lattice corners, counter-clockwise seen from outside
};

Face MakeFace(const Lattice& voxel, int dir) {
  Face face;
  face.voxel = voxel;
  face.dir = dir;
  const int a = DirAxis(dir), b1 = (a + 1) % 3, b2 = (a + 2) % 3;
  Lattice base = voxel;
  if (DirSign(dir) > 0) base[a] += 1;
  // (b1, b2) offsets; b1 x b2 = +a, so this order is counter-clockwise about +a.
  const int ccw[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int c = 0; c < 4; ++c) {
    const int src = DirSign(dir) > 0 ? c : (4 - c) % 4;  // reversed about -a
    Lattice p = base;
    p[b1] += ccw[src][0];
    p[b2] += ccw[src][1];
    face.corners[static_cast<size_t>(c)] = p;
  }
  return face;
}

class BoundaryMesher {
 public:
  explicit BoundaryMesher(const VoxelGrid& grid) : grid_(grid) {}

  TriangleMesh Run() {
    CollectFaces();
    const size_t num_faces = faces_.size();
    DisjointSets slots(4 * num_faces);
    // For each face edge (corner c -> c + 1): the neighbouring face across it.
    std::vector<std::array<int64_t, 4>> neighbour(num_faces);
    std::vector<std::array<bool, 4>> pinched(num_faces);
    for (size_t f = 0; f < num_faces; ++f) {
      for (int e = 0; e < 4; ++e) {
        bool is_pinched = false;
        const int64_t g = NeighbourAcross(faces_[f], e, &is_pinched);
        neighbour[f][static_cast<size_t>(e)] = g;
        pinched[f][static_cast<size_t>(e)] = is_pinched;
        const Face& other = faces_[static_cast<size_t>(g)];
        for (int end = 0; end < 2; ++end) {
          const Lattice& p = faces_[f].corners[static_cast<size_t>((e + end) % 4)];
          const auto it = std::find(other.corners.begin(), other.corners.end(), p);
          slots.Union(4 * f + static_cast<size_t>((e + end) % 4),
                      4 * static_cast<size_t>(g) + static_cast<size_t>(it - other.corners.begin()));
        }
      }
    }
    TriangleMesh mesh;
    std::vector<int32_t> vertex_of_root(4 * num_faces, -1);
    auto corner_vertex = [&](size_t f, int c) {
      const size_t root = slots.Find(4 * f + static_cast<size_t>(c));
      int32_t& v = vertex_of_root[root];
      if (v < 0) {
        v = AddVertex(&mesh, faces_[f].corners[static_cast<size_t>(c)].cast<double>());
      }
      return v;
    };
    // Midpoint vertices of pinched edges, one per pair of joined faces.
    std::map<std::pair<int64_t, int64_t>, int32_t> midpoints;
    for (size_t f = 0; f < num_faces; ++f) {
      const Face& face = faces_[f];
      int32_t c[4];
      for (int k = 0; k < 4; ++k)
        c[k] = corner_vertex(f, k);
      const bool any_pinched =
          std::find(pinched[f].begin(), pinched[f].end(), true) != pinched[f].end();
      if (!any_pinched) {
        mesh.triangles.push_back({c[0], c[1], c[2]});
        mesh.triangles.push_back({c[0], c[2], c[3]});
        continue;
      }
      // Fan around the face centre over corners and the pinched edges' midpoints.
      std::vector<int32_t> polygon;
      for (int k = 0; k < 4; ++k) {
        polygon.push_back(c[k]);
        if (!pinched[f][static_cast<size_t>(k)]) continue;
        const int64_t g = neighbour[f][static_cast<size_t>(k)];
        const auto self = static_cast<int64_t>(f);
        auto [it, inserted] = midpoints.try_emplace({std::min(self, g), std::max(self, g)}, 0);
        if (inserted) {
          const Eigen::Vector3d mid =
              0.5 * (face.corners[static_cast<size_t>(k)].cast<double>() +
                     face.corners[static_cast<size_t>((k + 1) % 4)].cast<double>());
          it->second = AddVertex(&mesh, mid);
        }
        polygon.push_back(it->second);
      }
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const Lattice& p : face.corners)
        centre += 0.25 * p.cast<double>();
      const int32_t mid = AddVertex(&mesh, centre);
      for (size_t k = 0; k < polygon.size(); ++k)
        mesh.triangles.push_back({mid, polygon[k], polygon[(k + 1) % polygon.size()]});
    }
    return mesh;
  }

 private:
  bool Occupied(const Lattice& v) const { return grid_.IsOccupied(v.x(), v.y(), v.z()); }

  void CollectFaces() {
    const auto& d = grid_.dims;
    for (int k = 0; k < d[2]; ++k) {
      for (int j = 0; j < d[1]; ++j) {
        for (int i = 0; i < d[0]; ++i) {
          if (!grid_.IsOccupied(i, j, k)) continue;
          const Lattice v(i, j, k);
          for (int dir = 0; dir < 6; ++dir) {
            if (Occupied(v + Step(DirAxis(dir), DirSign(dir)))) continue;
            keys_.push_back(FaceKey(v, dir));
            faces_.push_back(MakeFace(v, dir));
          }
        }
      }
    }
  }

  // Keys grow with (voxel index, dir), the order CollectFaces emits faces in.
  int64_t FaceKey(const Lattice& v, int dir) const {
    return static_cast<int64_t>(grid_.Index(v.x(), v.y(), v.z())) * 6 + dir;
  }

  int64_t FindFace(const Lattice& v, int dir) const {
    const int64_t key = FaceKey(v, dir);
    const auto it = std::lower_bound(keys_.begin(), keys_.end(), key);
    return it != keys_.end() && *it == key ? it - keys_.begin() : -1;
  }

  // The face joined to `face` across its edge e (corners e, e + 1). Around that lattice
  // edge lie the face's voxel v, v + s (s: towards the edge in the face's plane), v + d + s
  // and the empty v + d. `pinched` is set when v + s is empty but v + d + s is occupied.
  int64_t NeighbourAcross(const Face& face, int e, bool* pinched) const {
    const Lattice& p = face.corners[static_cast<size_t>(e)];
    const Lattice& q = face.corners[static_cast<size_t>((e + 1) % 4)];
    const int a = DirAxis(face.dir);
    // The in-plane axis along which the edge is constant, and which side of the face it is.
    int s_axis = -1;
    for (int ax = 0; ax < 3; ++ax) {
      if (ax != a && p[ax] == q[ax]) s_axis = ax;
    }
    const int s_sign = p[s_axis] > face.voxel[s_axis] ? 1 : -1;
    const Lattice s = Step(s_axis, s_sign), d = Step(a, DirSign(face.dir));
    const bool side = Occupied(face.voxel + s), diagonal = Occupied(face.voxel + s + d);
    *pinched = !side && diagonal;
    int64_t g = -1;
    if (side && diagonal) {
      g = FindFace(face.voxel + s + d, MakeDir(s_axis, -s_sign));  // concave corner
    } else if (side) {
      g = FindFace(face.voxel + s, face.dir);  // flat continuation
    } else {
      g = FindFace(face.voxel, MakeDir(s_axis, s_sign));  // convex: wrap around the voxel
    }
    return g;
  }

  int32_t AddVertex(TriangleMesh* mesh, const Eigen::Vector3d& lattice) const {
    mesh->vertices.push_back((grid_.origin + grid_.voxel_size * lattice).cast<float>());
    return static_cast<int32_t>(mesh->vertices.size() - 1);
  }

  const VoxelGrid& grid_;
  std::vector<Face> faces_;
  std::vector<int64_t> keys_;
};

}  // namespace

TriangleMesh ExtractBoundaryMesh(const VoxelGrid& grid) {
  return BoundaryMesher(grid).Run();
}

}  // namespace silnet::aggregator

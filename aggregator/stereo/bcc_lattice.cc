#include "aggregator/stereo/bcc_lattice.h"

#include <algorithm>
#include <cmath>

#include "shared/util/check.h"

namespace silnet::aggregator {

double SignedVolume6(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a));
}

Tetrahedron PositivelyOriented(const Tetrahedron& tet,
                               const std::vector<Eigen::Vector3d>& vertices) {
  if (SignedVolume6(vertices[tet[0]], vertices[tet[1]], vertices[tet[2]], vertices[tet[3]]) >= 0)
    return tet;
  return {tet[0], tet[1], tet[3], tet[2]};
}

TetMesh BuildBccLattice(const WorldBox& box, double spacing) {
  SILNET_CHECK(!box.isEmpty());
  SILNET_CHECK(spacing > 0);
  const Eigen::Vector3d size = box.sizes();
  std::array<int64_t, 3> n{};
  for (int a = 0; a < 3; ++a)
    n[a] = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(size[a] / spacing - 1e-9)));
  const int64_t nodes = (n[0] + 1) * (n[1] + 1) * (n[2] + 1);
  const int64_t centres = (n[0] + 2) * (n[1] + 2) * (n[2] + 2);
  SILNET_CHECK_MSG(nodes + centres < (int64_t{1} << 31), "BCC lattice too large");

  TetMesh mesh;
  mesh.vertices.reserve(static_cast<size_t>(nodes + centres));
  for (int64_t k = 0; k <= n[2]; ++k)
    for (int64_t j = 0; j <= n[1]; ++j)
      for (int64_t i = 0; i <= n[0]; ++i)
        mesh.vertices.push_back(box.min() + spacing * Eigen::Vector3d(i, j, k));
  for (int64_t k = -1; k <= n[2]; ++k)
    for (int64_t j = -1; j <= n[1]; ++j)
      for (int64_t i = -1; i <= n[0]; ++i)
        mesh.vertices.push_back(box.min() + spacing * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));

  const auto node = [&](const std::array<int64_t, 3>& p) {
    return static_cast<int32_t>(p[0] + (n[0] + 1) * (p[1] + (n[1] + 1) * p[2]));
  };
  // Centre of the cube whose lowest node is p (each coordinate from -1 to n).
  const auto centre = [&](const std::array<int64_t, 3>& p) {
    return static_cast<int32_t>(nodes + (p[0] + 1) +
                                (n[0] + 2) * ((p[1] + 1) + (n[1] + 2) * (p[2] + 1)));
  };

  mesh.tetrahedra.reserve(
      static_cast<size_t>(12 * n[0] * n[1] * n[2] + 4 * (n[0] * n[1] + n[1] * n[2] + n[0] * n[2])));
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    std::array<int64_t, 3> p{};
    for (p[axis] = 0; p[axis] <= n[axis]; ++p[axis]) {
      for (p[v] = 0; p[v] < n[v]; ++p[v]) {
        for (p[u] = 0; p[u] < n[u]; ++p[u]) {
          std::array<int64_t, 3> below = p;
          --below[axis];
          const int32_t c1 = centre(below), c2 = centre(p);
          std::array<std::array<int64_t, 3>, 4> corner{p, p, p, p};
          ++corner[1][u];
          ++corner[2][u];
          ++corner[2][v];
          ++corner[3][v];
          for (int e = 0; e < 4; ++e) {
            const Tetrahedron tet{c1, c2, node(corner[e]), node(corner[(e + 1) % 4])};
            mesh.tetrahedra.push_back(PositivelyOriented(tet, mesh.vertices));
          }
        }
      }
    }
  }
  return mesh;
}

}  // namespace silnet::aggregator

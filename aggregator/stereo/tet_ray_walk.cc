#include "aggregator/stereo/tet_ray_walk.h"

#include <Eigen/Geometry>
#include <limits>

#include "shared/util/check.h"

namespace silnet::aggregator {

TetRayWalker::TetRayWalker(const TetMesh& mesh, const std::vector<CellFace>& faces)
    : mesh_(mesh), across_(4 * mesh.tetrahedra.size(), -1) {
  SILNET_CHECK(faces.size() == 4 * mesh.tetrahedra.size());
  for (size_t k = 0; k + 1 < faces.size(); ++k) {
    const CellFace& a = faces[k];
    const CellFace& b = faces[k + 1];
    if (a.ids != b.ids) continue;
    across_[4 * static_cast<size_t>(a.cell) + a.opposite] = b.cell;
    across_[4 * static_cast<size_t>(b.cell) + b.opposite] = a.cell;
  }
}

int32_t TetRayWalker::Exit(int32_t cell, int32_t previous, const Eigen::Vector3d& origin,
                           const Eigen::Vector3d& direction, double* s) const {
  const Tetrahedron& t = mesh_.tetrahedra[static_cast<size_t>(cell)];
  double best = std::numeric_limits<double>::infinity(), fallback = best;
  int best_face = -1, fallback_face = -1;
  for (int o = 0; o < 4; ++o) {
    const Eigen::Vector3d& a = mesh_.vertices[t[(o + 1) % 4]];
    const Eigen::Vector3d& b = mesh_.vertices[t[(o + 2) % 4]];
    const Eigen::Vector3d& c = mesh_.vertices[t[(o + 3) % 4]];
    Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.dot(mesh_.vertices[t[o]] - a) > 0) normal = -normal;  // away from corner o
    const double along = normal.dot(direction);
    if (!(along > 0)) continue;  // the ray does not leave through this face
    const double at = std::max(*s, normal.dot(a - origin) / along);
    const bool back = across_[4 * static_cast<size_t>(cell) + o] == previous && previous >= 0;
    if (back && at < fallback) {
      fallback = at;
      fallback_face = o;
    } else if (!back && at < best) {
      best = at;
      best_face = o;
    }
  }
  if (best_face < 0) {
    best = fallback;
    best_face = fallback_face;
  }
  if (best_face < 0) return -1;
  *s = best;
  return across_[4 * static_cast<size_t>(cell) + best_face];
}

}  // namespace silnet::aggregator

#include "aggregator/pairwise/frontier_matching.h"

#include <Eigen/Geometry>
#include <cmath>

#include "shared/silhouette/hull_tangents.h"

namespace silnet::aggregator {

OuterTangents ComputeOuterTangents(const SilhouetteHull& hull, const Eigen::Vector3d& epipole) {
  OuterTangents t;
  const auto tangents = TangentsFromPoint(hull, epipole);
  if (!tangents) return t;
  t.exists = true;
  const int vertices[2] = {tangents->left, tangents->right};
  for (int s = 0; s < 2; ++s) {
    t.point[s] = hull.vertex(vertices[s]);
    t.valid[s] = !hull.vertex_on_clipped_edge(vertices[s]);
  }
  return t;
}

OuterTangents Interpolate(const OuterTangents& a, const OuterTangents& b, double fraction) {
  if (fraction <= 0.0 || !b.exists) return fraction <= 0.0 ? a : OuterTangents{};
  if (fraction >= 1.0 || !a.exists) return fraction >= 1.0 ? b : OuterTangents{};
  OuterTangents t;
  t.exists = true;
  for (int s = 0; s < 2; ++s) {
    t.point[s] = (1.0 - fraction) * a.point[s] + fraction * b.point[s];
    t.valid[s] = a.valid[s] && b.valid[s];
  }
  return t;
}

int MatchTangents(const EpipolarModel& model, const OuterTangents& ti, const OuterTangents& tj,
                  FrontierMatch out[2]) {
  if (!ti.exists || !tj.exists) return 0;
  // Pencil coordinates in view j of the transferred tangents of i and of j's own tangents.
  Eigen::Vector2d transferred[2], own[2];
  for (int s = 0; s < 2; ++s) {
    transferred[s] = model.pencil_j.Coordinates(model.LineInJ(ti.point[s])).normalized();
    own[s] =
        model.pencil_j.Coordinates(model.pencil_j.e.cross(tj.point[s].homogeneous())).normalized();
  }
  auto sine = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    return std::abs(p.x() * q.y() - p.y() * q.x());
  };
  const bool straight = sine(transferred[0], own[0]) + sine(transferred[1], own[1]) <=
                        sine(transferred[0], own[1]) + sine(transferred[1], own[0]);
  int count = 0;
  for (int s = 0; s < 2; ++s) {
    const int partner = straight ? s : 1 - s;
    if (!ti.valid[s] || !tj.valid[partner]) continue;
    out[count++] = FrontierMatch{ti.point[s], tj.point[partner], s, partner};
  }
  return count;
}

}  // namespace silnet::aggregator

#include "aggregator/stereo/tet_ray_walk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "aggregator/stereo/red_green_mesh.h"
#include "aggregator/stereo/tet_point_locator.h"

namespace silnet::aggregator {
namespace {

// The parameter range [first, second] of the ray o + s d inside tetrahedron t (empty when
// first > second), by clipping against its four faces.
std::pair<double, double> RayInside(const TetMesh& mesh, int32_t t, const Eigen::Vector3d& o,
                                    const Eigen::Vector3d& d) {
  double lo = -1e300, hi = 1e300;
  const Tetrahedron& c = mesh.tetrahedra[static_cast<size_t>(t)];
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d& a = mesh.vertices[c[(k + 1) % 4]];
    Eigen::Vector3d n =
        (mesh.vertices[c[(k + 2) % 4]] - a).cross(mesh.vertices[c[(k + 3) % 4]] - a);
    if (n.dot(mesh.vertices[c[k]] - a) > 0) n = -n;  // outwards
    const double along = n.dot(d), at = n.dot(a - o);
    if (along > 0)
      hi = std::min(hi, at / along);
    else if (along < 0)
      lo = std::max(lo, at / along);
    else if (at < 0)
      return {1, 0};
  }
  return {lo, hi};
}

TEST(TetRayWalker, VisitsEveryCellTheRayCrossesInOrderUntilItLeavesTheMesh) {
  const WorldBox box(Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 0.75, 0.5));
  std::mt19937 random(3);
  RedGreenMesh refined(BuildBccLattice(box, 0.25));
  for (int round = 0; round < 3; ++round) {
    std::vector<int32_t> chosen;
    for (int32_t leaf : refined.Leaves())
      if (std::uniform_real_distribution<double>(0, 1)(random) < 0.15) chosen.push_back(leaf);
    refined.Refine(chosen);
  }
  const TetMesh mesh = refined.Conform().mesh;
  const TetRayWalker walker(mesh, SortedCellFaces(mesh));
  const TetPointLocator locator(mesh, 0.05);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int ray = 0; ray < 300; ++ray) {
    const Eigen::Vector3d origin(unit(random), 0.75 * unit(random), 0.5 * unit(random));
    const Eigen::Vector3d direction =
        Eigen::Vector3d(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5).normalized();
    const int32_t start = locator.Locate(origin);
    ASSERT_GE(start, 0);
    std::vector<int32_t> cells;
    double reached = 0;
    walker.Walk(start, origin, direction, [&](int32_t t, double entry, double exit) {
      // Each cell holds the piece of the ray it is given, which begins where the last ended.
      const auto [lo, hi] = RayInside(mesh, t, origin, direction);
      EXPECT_NEAR(entry, reached, 1e-12) << "ray " << ray;
      EXPECT_LE(lo, entry + 1e-9) << "ray " << ray;
      EXPECT_NEAR(exit, hi, 1e-9) << "ray " << ray;
      reached = exit;
      cells.push_back(t);
      return true;
    });
    // ... until the ray leaves the mesh.
    EXPECT_LT(locator.Locate(origin + (reached + 1e-7) * direction), 0) << "ray " << ray;
    EXPECT_GT(reached, 0.0);
    // Every cell a fine sampling of the ray finds is visited.
    const std::set<int32_t> visited(cells.begin(), cells.end());
    EXPECT_EQ(visited.size(), cells.size()) << "a cell visited twice, ray " << ray;
    for (double s = 0; s < reached; s += 1e-3) {
      const int32_t t = locator.Locate(origin + s * direction);
      if (t < 0 || visited.count(t)) continue;
      const auto [lo, hi] = RayInside(mesh, t, origin, direction);
      EXPECT_LT(hi - lo, 1e-9) << "cell " << t << " crossed but not visited, ray " << ray;
    }
  }
}

TEST(TetRayWalker, StopsWhereTheVisitSays) {
  const TetMesh mesh =
      BuildBccLattice(WorldBox(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), 0.25);
  const TetRayWalker walker(mesh, SortedCellFaces(mesh));
  const TetPointLocator locator(mesh, 0.1);
  const Eigen::Vector3d origin(0.1, 0.2, 0.3);
  int calls = 0;
  const size_t visited =
      walker.Walk(locator.Locate(origin), origin, Eigen::Vector3d(1, 0.3, 0.2).normalized(),
                  [&](int32_t, double, double) { return ++calls < 4; });
  EXPECT_EQ(visited, 4u);
  EXPECT_EQ(calls, 4);
}

}  // namespace
}  // namespace silnet::aggregator

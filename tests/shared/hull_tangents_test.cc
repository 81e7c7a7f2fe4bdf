#include "shared/silhouette/hull_tangents.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <random>

#include "tests/shared/silhouette_test_util.h"

namespace silnet {
namespace {

// True if the line through homogeneous p and vertex v has every hull vertex on the side
// `side` (+1 left, -1 right) or on the line.
bool IsTangent(const SilhouetteHull& hull, const Eigen::Vector3d& p, int v, double side) {
  const Eigen::Vector3d line = TangentLine(hull, p.z() < 0 ? Eigen::Vector3d(-p) : p, v);
  const double scale = line.head<2>().norm();
  for (const Eigen::Vector2d& x : hull.vertices()) {
    // line = p x v; for w > 0, line . x > 0 means x is left of p -> v.
    if (side * line.dot(x.homogeneous()) / scale < -1e-7) return false;
  }
  return true;
}

TEST(HullTangents, OuterTangentsFromPointsAgreeWithBruteForce) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int cases = 0, inside = 0;
  SilhouetteHull hull;
  for (int trial = 0; cases < 10000; ++trial) {
    while (trial % 50 == 0 || hull.size() < 3) {
      hull = ComputeSilhouetteHull(
          testing::RandomBlobMask(rng, 320, 240, 1 + trial % 3, trial % 2 == 0));
      ++trial;
    }
    // Points near and far, finite and at infinity.
    Eigen::Vector3d p;
    if (trial % 7 == 0) {
      p = Eigen::Vector3d(u(rng), u(rng), 0.0);
    } else {
      const double range = trial % 3 == 0 ? 5000.0 : 400.0;
      p = Eigen::Vector3d(160 + range * u(rng), 120 + range * u(rng), 1.0);
      if (trial % 11 == 0) p *= -2.5;  // scale and sign of a homogeneous point do not matter
    }
    const auto fast = TangentsFromPoint(hull, p);
    const auto slow = TangentsFromPointLinear(hull, p);
    ASSERT_EQ(fast.has_value(), slow.has_value()) << "trial " << trial;
    ++cases;
    if (!fast) {
      ++inside;
      ASSERT_NE(p.z(), 0.0);
      EXPECT_TRUE(hull.Contains(p.hnormalized()));
      continue;
    }
    EXPECT_TRUE(IsTangent(hull, p, fast->left, 1.0)) << "trial " << trial;
    EXPECT_TRUE(IsTangent(hull, p, fast->right, -1.0)) << "trial " << trial;
  }
  EXPECT_GT(inside, 10);
}

TEST(HullTangents, SupportingVertexMatchesTheTable) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 2.0 * std::numbers::pi);
  for (int trial = 0; trial < 200; ++trial) {
    const SilhouetteHull hull =
        ComputeSilhouetteHull(testing::RandomBlobMask(rng, 320, 240, 2, trial % 2 == 0));
    if (hull.empty()) continue;
    for (int k = 0; k < 50; ++k) {
      const double angle = u(rng);
      const int v = SupportingVertex(hull, angle);
      // A line of this direction through v keeps the hull on its left.
      const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
      for (const Eigen::Vector2d& x : hull.vertices()) {
        const Eigen::Vector2d r = x - hull.vertex(v);
        EXPECT_GE(d.x() * r.y() - d.y() * r.x(), -1e-9);
      }
    }
  }
}

TEST(HullTangents, NoTangentsFromInsideOrFromDegenerateHulls) {
  const SilhouetteHull hull =
      ComputeSilhouetteHull(testing::EllipseMask(100, 100, 50, 50, 20, 20, 0));
  EXPECT_FALSE(TangentsFromPoint(hull, Eigen::Vector3d(50, 50, 1)).has_value());
  EXPECT_TRUE(TangentsFromPoint(hull, Eigen::Vector3d(500, 50, 1)).has_value());
  EXPECT_FALSE(TangentsFromPoint(SilhouetteHull(), Eigen::Vector3d(0, 0, 1)).has_value());
}

}  // namespace
}  // namespace silnet

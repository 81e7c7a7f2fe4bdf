#include "sim/scene/primitive.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace silnet::sim {
namespace {

Primitive RandomPrimitive(std::mt19937_64& rng, bool capsule) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Matrix3d axes =
      Eigen::AngleAxisd(3.0 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
          .toRotationMatrix();
  if (capsule) {
    return Primitive::MakeCapsule(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.3,
                                  Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.5,
                                  0.05 + 0.1 * std::abs(u(rng)), axes, 0, 0);
  }
  return Primitive::MakeEllipsoid(
      Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.3,
      Eigen::Vector3d(0.1 + 0.2 * std::abs(u(rng)), 0.05 + 0.2 * std::abs(u(rng)),
                      0.1 + 0.3 * std::abs(u(rng))),
      axes, 0, 0);
}

TEST(Primitive, RayHitsLieOnTheSurfaceAndNothingIsCrossedBefore) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int hits = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Primitive p = RandomPrimitive(rng, trial % 2 == 0);
    const Eigen::Vector3d origin = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized() * 3.0;
    const Eigen::Vector3d target = p.center + 0.4 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Vector3d dir = (target - origin).normalized();
    double t = 0.0;
    const bool hit = p.Intersect(origin, dir, &t);
    // Brute force: the first sample inside along the ray.
    double first_inside = -1.0;
    for (double s = 0.0; s < 6.0; s += 1e-4) {
      if (p.Contains(origin + s * dir)) {
        first_inside = s;
        break;
      }
    }
    if (hit) {
      ++hits;
      EXPECT_GE(first_inside, 0.0);
      EXPECT_NEAR(t, first_inside, 2e-4);
      const Eigen::Vector3d point = origin + t * dir;
      const Eigen::Vector3d n = p.Normal(point);
      EXPECT_TRUE(p.Contains(point - 1e-6 * n));
      EXPECT_FALSE(p.Contains(point + 1e-6 * n));
    } else {
      EXPECT_LT(first_inside, 0.0) << "missed a primitive the ray enters at " << first_inside;
    }
  }
  EXPECT_GT(hits, 300);
}

TEST(Primitive, SurfaceSamplesAreOnTheSurface) {
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 50; ++trial) {
    const Primitive p = RandomPrimitive(rng, trial % 2 == 0);
    for (const Eigen::Vector3d& x : p.SampleSurface(100, rng)) {
      const Eigen::Vector3d n = p.Normal(x);
      EXPECT_TRUE(p.Contains(x - 1e-7 * n));
      EXPECT_FALSE(p.Contains(x + 1e-7 * n));
    }
  }
}

TEST(Primitive, TransformedKeepsContainment) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.5, -2.0, 3.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Primitive p = RandomPrimitive(rng, trial % 2 == 0);
    const Primitive q = p.Transformed(r, t);
    for (int k = 0; k < 50; ++k) {
      const Eigen::Vector3d x(0.6 * u(rng), 0.6 * u(rng), 0.6 * u(rng));
      EXPECT_EQ(p.Contains(x), q.Contains(r * x + t));
      EXPECT_LE((x - p.BoundingCenter()).norm() - 1e-9, p.Contains(x) ? p.BoundingRadius() : 1e9);
    }
  }
}

}  // namespace
}  // namespace silnet::sim

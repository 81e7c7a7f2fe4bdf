#include "shared/geometry/epipolar.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace silnet {
namespace {

CameraModel CameraAt(const Eigen::Vector3d& center, double focal, double offset) {
  CameraModel c;
  c.width = 640;
  c.height = 480;
  c.K << focal, 0, 318, 0, focal, 243, 0, 0, 1;
  c.R = LookAtRotation(center, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitZ());
  c.t = -c.R * center;
  c.time_offset = offset;
  return c;
}

TEST(Epipolar, ProjectedPointsSatisfyTheEpipolarConstraint) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double a = 3.0 * u(rng), b = a + 1.0 + u(rng);
    const CameraModel ci =
        CameraAt({4 * std::cos(a), 4 * std::sin(a), 1.5 + u(rng)}, 520 + 40 * u(rng), 0);
    const CameraModel cj =
        CameraAt({4 * std::cos(b), 4 * std::sin(b), 1.5 + u(rng)}, 520 + 40 * u(rng), 0);
    const Eigen::Matrix3d f = FundamentalFromCameras(ci, cj);
    EXPECT_NEAR(f.norm(), 1.0, 1e-12);
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d X(u(rng), u(rng), 1.0 + u(rng));
      EXPECT_LT(SymmetricEpipolarDistance(f, *ci.Project(X), *cj.Project(X)), 1e-8);
    }
    // Epipoles are the other camera's centre seen in each view.
    const Eigen::Vector3d e_i = EpipoleInFirstView(f);
    const Eigen::Vector3d expected_i = ci.K * (ci.R * cj.Center() + ci.t);
    EXPECT_LT(e_i.normalized().cross(expected_i.normalized()).norm(), 1e-9);
    const Eigen::Vector3d e_j = EpipoleInSecondView(f);
    const Eigen::Vector3d expected_j = cj.K * (cj.R * ci.Center() + cj.t);
    EXPECT_LT(e_j.normalized().cross(expected_j.normalized()).norm(), 1e-9);
  }
}

TEST(Epipolar, NormalizeFundamentalRemovesScaleAndSign) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Random();
  EXPECT_LT((NormalizeFundamental(f) - NormalizeFundamental(-3.5 * f)).norm(), 1e-12);
}

TEST(Epipolar, PointLineDistanceIsInPixels) {
  const Eigen::Vector3d line(0, 2, -10);  // y = 5
  EXPECT_DOUBLE_EQ(PointLineDistance(line, {3, 8}), 3.0);
}

TEST(Epipolar, PairTimingMapsSimultaneousFrames) {
  CameraModel ci, cj;
  ci.fps = 30;
  ci.time_offset = 4.25;
  cj.fps = 30;
  cj.time_offset = -7.5;
  const PairTiming equal = PairTimingFromCameras(ci, cj);
  EXPECT_DOUBLE_EQ(equal.offset, 4.25 + 7.5);
  EXPECT_DOUBLE_EQ(equal.rate, 1.0);
  cj.fps = 25;
  const PairTiming timing = PairTimingFromCameras(ci, cj);
  for (double k : {0.0, 13.0, 250.5}) {
    EXPECT_NEAR(ci.ExposureTime(k), cj.ExposureTime(timing.offset + timing.rate * k), 1e-12);
  }
}

}  // namespace
}  // namespace silnet

// The relative pose refined as an essential matrix on its correspondences.

#include "aggregator/calibration/essential_refinement.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <random>

namespace silnet::aggregator {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

CameraModel Camera(const Eigen::Matrix3d& R, const Eigen::Vector3d& centre) {
  CameraModel c;
  c.width = 640;
  c.height = 480;
  c.K << 500, 0, 322, 0, 500, 236, 0, 0, 1;
  c.R = R;
  c.t = -R * centre;
  return c;
}

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() / kDegree;
}

// Two cameras 60 deg apart looking at a cloud of points; pixels with 0.3 px noise and a tenth
// of the correspondences wrong by up to 20 px.
struct TwoViews {
  CameraModel i, j;
  RelativePose truth;
  std::vector<Correspondence> matches;

  explicit TwoViews(unsigned seed) {
    const Eigen::Matrix3d r_j = Eigen::AngleAxisd(-60 * kDegree, Eigen::Vector3d::UnitY()).matrix();
    i = Camera(Eigen::Matrix3d::Identity(), {0, 0, -4});
    j = Camera(r_j, r_j.transpose() * Eigen::Vector3d(0, 0, -4));
    truth.R = j.R * i.R.transpose();
    truth.t = (j.t - truth.R * i.t).normalized();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> box(-1.5, 1.5), wrong(-20, 20);
    std::normal_distribution<double> noise(0.0, 0.3);
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d x(box(rng), box(rng), box(rng));
      Correspondence c;
      c.x_i = *i.Project(x) + Eigen::Vector2d(noise(rng), noise(rng));
      c.x_j = *j.Project(x) + Eigen::Vector2d(noise(rng), noise(rng));
      if (k % 10 == 0) c.x_j += Eigen::Vector2d(wrong(rng), wrong(rng));
      matches.push_back(c);
    }
  }
};

TEST(EssentialRefinement, ReachesTheTruePoseFromFiveDegreesOff) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const TwoViews views(seed);
    RelativePose start = views.truth;
    start.R = Eigen::AngleAxisd(5 * kDegree, Eigen::Vector3d(1, 2, 3).normalized()) * start.R;
    start.t = (start.t + Eigen::Vector3d(0.05, -0.05, 0.03)).normalized();
    const RelativePose refined = RefineRelativePose(views.i, views.j, views.matches, start);
    EXPECT_LT(AngleDeg(refined.R, views.truth.R), 0.25) << "seed " << seed;
    EXPECT_LT(std::acos(std::min(1.0, refined.t.dot(views.truth.t))) / kDegree, 0.3)
        << "seed " << seed;
    EXPECT_NEAR(refined.t.norm(), 1.0, 1e-9);
    EXPECT_NEAR(refined.R.determinant(), 1.0, 1e-9);
  }
}

TEST(EssentialRefinement, TooFewCorrespondencesLeaveTheStartAsItIs) {
  TwoViews views(1);
  views.matches.resize(4);
  RelativePose start = views.truth;
  start.R = Eigen::AngleAxisd(5 * kDegree, Eigen::Vector3d::UnitX()) * start.R;
  const RelativePose refined = RefineRelativePose(views.i, views.j, views.matches, start);
  EXPECT_TRUE(refined.R.isApprox(start.R));
  EXPECT_TRUE(refined.t.isApprox(start.t));
}

}  // namespace
}  // namespace silnet::aggregator

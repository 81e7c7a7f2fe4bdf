#include "shared/geometry/camera_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>

#include "shared/util/check.h"

namespace silnet {
namespace {

CameraModel RandomCamera(std::mt19937_64& rng, bool distorted) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  CameraModel c;
  c.width = 640;
  c.height = 480;
  c.K << 500 + 50 * u(rng), 0, 320 + 10 * u(rng), 0, 505 + 50 * u(rng), 240 + 10 * u(rng), 0, 0, 1;
  if (distorted)
    c.dist << 0.1 * u(rng), 0.02 * u(rng), 0.001 * u(rng), 0.001 * u(rng), 0.005 * u(rng);
  c.R = Eigen::AngleAxisd(0.3 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized())
            .toRotationMatrix();
  c.t = Eigen::Vector3d(0.5 * u(rng), 0.5 * u(rng), 4.0 + u(rng));
  c.fps = 25 + 5 * u(rng);
  c.time_offset = 10 * u(rng);
  return c;
}

Eigen::Vector3d PointInView(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Eigen::Vector3d(1.2 * u(rng), 0.9 * u(rng), 0.8 * u(rng));
}

TEST(CameraModel, ProjectionMatchesOpenCvProjectPoints) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const CameraModel c = RandomCamera(rng, true);
    cv::Mat K, dist, R;
    cv::eigen2cv(c.K, K);
    cv::eigen2cv(Eigen::Matrix<double, 1, 5>(c.dist.transpose()), dist);
    cv::eigen2cv(c.R, R);
    cv::Mat rvec;
    cv::Rodrigues(R, rvec);
    const cv::Mat tvec = (cv::Mat_<double>(3, 1) << c.t.x(), c.t.y(), c.t.z());
    std::vector<cv::Point3d> points;
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d X = PointInView(rng);
      points.emplace_back(X.x(), X.y(), X.z());
    }
    std::vector<cv::Point2d> reference;
    cv::projectPoints(points, rvec, tvec, K, dist, reference);
    for (size_t i = 0; i < points.size(); ++i) {
      const auto pixel = c.Project({points[i].x, points[i].y, points[i].z});
      ASSERT_TRUE(pixel.has_value());
      EXPECT_NEAR(pixel->x(), reference[i].x, 1e-9);
      EXPECT_NEAR(pixel->y(), reference[i].y, 1e-9);
    }
  }
}

TEST(CameraModel, UndistortInvertsDistort) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-0.7, 0.7);
  for (int trial = 0; trial < 200; ++trial) {
    const CameraModel c = RandomCamera(rng, true);
    const Eigen::Vector2d n(u(rng), u(rng) * 0.75);
    EXPECT_LT((c.Undistort(c.Distort(n)) - n).norm(), 1e-12);
  }
}

TEST(CameraModel, PixelRayPointsAtTheProjectedPoint) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const CameraModel c = RandomCamera(rng, trial % 2 == 0);
    const Eigen::Vector3d X = PointInView(rng);
    const Eigen::Vector3d x_cam = c.R * X + c.t;
    const Eigen::Vector3d ray = c.PixelRay(*c.Project(X));
    EXPECT_LT((ray.normalized() - x_cam.normalized()).norm(), 1e-10);
    // UndistortPixel gives the pinhole projection K x_cam.
    const Eigen::Vector2d pinhole = (c.K * x_cam).hnormalized();
    EXPECT_LT((c.UndistortPixel(*c.Project(X)) - pinhole).norm(), 1e-7);
    EXPECT_LT((c.ProjectionMatrix() * X.homogeneous()).hnormalized().x() - pinhole.x(), 1e-9);
  }
}

TEST(CameraModel, PointsBehindTheCameraDoNotProject) {
  CameraModel c;
  c.t = Eigen::Vector3d(0, 0, -1);
  EXPECT_FALSE(c.Project(Eigen::Vector3d::Zero()).has_value());
}

TEST(CameraModel, InImageUsesPixelCentreConvention) {
  CameraModel c;
  c.width = 4;
  c.height = 3;
  EXPECT_TRUE(c.InImage({-0.5, -0.5}));
  EXPECT_TRUE(c.InImage({3.5, 2.5}));
  EXPECT_FALSE(c.InImage({3.51, 1.0}));
  EXPECT_FALSE(c.InImage({1.0, -0.51}));
}

TEST(CameraModel, ExposureTimeAndFrameAtAreInverse) {
  CameraModel c;
  c.fps = 25.0;
  c.time_offset = 3.25;
  EXPECT_DOUBLE_EQ(c.ExposureTime(0.0), 3.25 / 25.0);
  EXPECT_NEAR(c.FrameAt(c.ExposureTime(17.5)), 17.5, 1e-12);
}

TEST(LookAtRotation, LooksAtTheTargetWithImageUpAlongWorldUp) {
  const Eigen::Vector3d center(4, 1, 2), target(0, 0, 1);
  CameraModel c;
  c.K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  c.R = LookAtRotation(center, target, Eigen::Vector3d::UnitZ());
  c.t = -c.R * center;
  EXPECT_NEAR((c.R * c.R.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(c.R.determinant(), 1.0, 1e-12);
  const Eigen::Vector2d p = *c.Project(target);
  EXPECT_NEAR(p.x(), 320, 1e-9);
  EXPECT_NEAR(p.y(), 240, 1e-9);
  // A point above the target appears higher in the image (smaller v).
  EXPECT_LT(c.Project(target + Eigen::Vector3d::UnitZ())->y(), 240);
  EXPECT_THROW(LookAtRotation(center, center, Eigen::Vector3d::UnitZ()), CheckError);
}

}  // namespace
}  // namespace silnet

#include "sim/camera_network.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "shared/util/check.h"

namespace silnet::sim {
namespace {

TEST(CameraNetwork, EveryLayoutLooksAtTheCaptureArea) {
  for (RigLayout layout : {RigLayout::kRing, RigLayout::kDome, RigLayout::kArc}) {
    CameraNetworkOptions o;
    o.cameras = 12;
    o.layout = layout;
    o.max_distortion = 0.1;
    o.fps_spread = 0.02;
    const auto cameras = MakeCameraNetwork(o);
    ASSERT_EQ(cameras.size(), 12u);
    std::set<std::string> ids;
    double min_elevation = 1e9, max_elevation = -1e9, min_az = 1e9, max_az = -1e9;
    for (const CameraModel& c : cameras) {
      ids.insert(c.id);
      const auto centre_pixel = c.Project(Eigen::Vector3d(0, 0, 0.9));
      ASSERT_TRUE(centre_pixel.has_value());
      EXPECT_TRUE(c.InImage(*centre_pixel)) << c.id;
      EXPECT_NEAR((c.Center() - Eigen::Vector3d(0, 0, 0.95)).norm(), 4.5, 0.3) << c.id;
      EXPECT_LE(std::abs(c.time_offset), 15.0);
      EXPECT_LE(std::abs(c.dist[0]), 0.1);
      EXPECT_NEAR(c.fps, 30.0, 0.61);
      const Eigen::Vector3d d = c.Center() - Eigen::Vector3d(0, 0, 0.95);
      const double elevation = std::asin(d.z() / d.norm()) * 180 / std::numbers::pi;
      min_elevation = std::min(min_elevation, elevation);
      max_elevation = std::max(max_elevation, elevation);
      const double az = std::atan2(d.y(), d.x()) * 180 / std::numbers::pi;
      min_az = std::min(min_az, az);
      max_az = std::max(max_az, az);
    }
    EXPECT_EQ(ids.size(), 12u);
    if (layout == RigLayout::kDome) {
      EXPECT_GT(max_elevation - min_elevation, 30.0);
    }
    if (layout == RigLayout::kRing) {
      EXPECT_LT(max_elevation - min_elevation, 15.0);
    }
    if (layout == RigLayout::kArc) {
      EXPECT_LT(max_az - min_az, 175.0);
    }
    // Intrinsics differ per camera.
    EXPECT_NE(cameras[0].K(0, 0), cameras[1].K(0, 0));
  }
}

TEST(CameraNetwork, CamerasAimAtTheTargetHeightWithinTheAimJitter) {
  for (double jitter : {0.0, 0.05}) {
    CameraNetworkOptions o;
    o.cameras = 10;
    o.layout = RigLayout::kDome;
    o.target_height = 1.4;
    o.aim_jitter = jitter;
    for (const CameraModel& c : MakeCameraNetwork(o)) {
      // The optical axis (the camera's z in the world) passes the aim point.
      const Eigen::Vector3d axis = c.R.row(2).transpose();
      const Eigen::Vector3d to_target = Eigen::Vector3d(0, 0, 1.4) - c.Center();
      const double miss = (to_target - to_target.dot(axis) * axis).norm();
      EXPECT_LE(miss, jitter * std::sqrt(2.0 + 0.36) + 1e-9) << c.id;
      EXPECT_NEAR(to_target.norm(), 4.5, 0.25) << c.id;
    }
  }
}

TEST(CameraNetwork, RejectsImpossibleOptionsWithAReason) {
  CameraNetworkOptions o;
  o.cameras = 1;
  EXPECT_THROW(MakeCameraNetwork(o), InputError);
  o = {};
  o.width = 0;
  EXPECT_THROW(MakeCameraNetwork(o), InputError);
  o = {};
  o.horizontal_fov_deg = 200;
  EXPECT_THROW(MakeCameraNetwork(o), InputError);
  o = {};
  o.aim_jitter = -0.1;
  EXPECT_THROW(MakeCameraNetwork(o), InputError);
  EXPECT_THROW(ParseRigLayout("circle"), InputError);
}

TEST(CameraNetwork, SameSeedSameCameras) {
  CameraNetworkOptions o;
  o.seed = 9;
  const auto a = MakeCameraNetwork(o), b = MakeCameraNetwork(o);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].K, b[i].K);
    EXPECT_EQ(a[i].R, b[i].R);
    EXPECT_EQ(a[i].time_offset, b[i].time_offset);
  }
}

}  // namespace
}  // namespace silnet::sim

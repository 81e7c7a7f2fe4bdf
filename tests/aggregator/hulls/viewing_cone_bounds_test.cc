// The box around the intersection of the viewing cones of silhouette rectangles, on random
// camera rigs: every point inside all the cones lies in it, and it is not much larger.

#include "aggregator/hulls/viewing_cone_bounds.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {
namespace {

// A camera `distance` from the origin in direction `from`, looking near the origin.
CameraModel CameraLookingAtOrigin(const Eigen::Vector3d& from, double distance, int index,
                                  std::mt19937& rng) {
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  CameraModel camera;
  camera.id = "cam" + std::to_string(index);
  camera.width = 640;
  camera.height = 480;
  camera.K << 800, 0, 320, 0, 800, 240, 0, 0, 1;
  const Eigen::Vector3d centre = distance * from.normalized();
  const Eigen::Vector3d aim(jitter(rng), jitter(rng), jitter(rng));
  camera.R = LookAtRotation(centre, aim, Eigen::Vector3d::UnitZ());
  camera.t = -camera.R * centre;
  return camera;
}

// True if the world point projects inside the rectangle's pixel area, in front of the camera.
bool InsideRect(const CameraModel& camera, const cv::Rect& rect, const Eigen::Vector3d& point) {
  const Eigen::Vector3d x = camera.ProjectionMatrix() * point.homogeneous();
  if (!(x.z() > 0)) return false;
  const double u = x.x() / x.z(), v = x.y() / x.z();
  return u >= rect.x - 0.5 && u <= rect.x + rect.width - 0.5 && v >= rect.y - 0.5 &&
         v <= rect.y + rect.height - 0.5;
}

TEST(ViewingConeBoundsTest, BoxHoldsEveryPointInsideAllConesOnRandomRigs) {
  std::mt19937 rng(20261129);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> views(3, 12), size(30, 400);
  std::uniform_real_distribution<double> unit(0, 1);
  int bounded = 0;
  for (int rig = 0; rig < 40; ++rig) {
    std::vector<CameraModel> cameras;
    std::vector<cv::Rect> rects;
    const int count = views(rng);
    for (int c = 0; c < count; ++c) {
      const Eigen::Vector3d from(normal(rng), normal(rng), 0.5 * normal(rng));
      cameras.push_back(CameraLookingAtOrigin(from, 3 + unit(rng), c, rng));
      // A rectangle around the origin's image (some reach the image border).
      const Eigen::Vector3d o = cameras.back().ProjectionMatrix() * Eigen::Vector4d(0, 0, 0, 1);
      const int u = static_cast<int>(o.x() / o.z()), v = static_cast<int>(o.y() / o.z());
      const int w = size(rng), h = size(rng);
      const int x0 = u - static_cast<int>(unit(rng) * w), y0 = v - static_cast<int>(unit(rng) * h);
      rects.push_back(cv::Rect(x0, y0, w, h) & cv::Rect(0, 0, 640, 480));
    }
    const ViewingConeBounds bounds = ComputeViewingConeBounds(cameras, rects);
    if (!bounds.success) {
      EXPECT_EQ(bounds.reason, "viewing cones do not bound a finite region") << "rig " << rig;
      continue;
    }
    ++bounded;
    // Points inside every cone, sampled in the box grown by half its size on every side, lie
    // in the box; their extent spans at least half of it along every axis.
    Eigen::AlignedBox3d inside_extent;
    const double tolerance = 1e-9 * (1 + bounds.box.max().norm() + bounds.box.min().norm());
    const Eigen::Vector3d low = bounds.box.min() - 0.5 * bounds.box.sizes();
    const Eigen::Vector3d span = 2 * bounds.box.sizes();
    for (int k = 0; k < 20000; ++k) {
      const Eigen::Vector3d point =
          low + span.cwiseProduct(Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
      bool inside = true;
      for (size_t c = 0; c < cameras.size() && inside; ++c)
        inside = InsideRect(cameras[c], rects[c], point);
      if (!inside) continue;
      inside_extent.extend(point);
      EXPECT_TRUE(bounds.box.exteriorDistance(point) <= tolerance)
          << "rig " << rig << ": a point inside every cone lies outside the box";
    }
    ASSERT_FALSE(inside_extent.isEmpty()) << "rig " << rig;
    const Eigen::Vector3d box_size = bounds.box.sizes(), inside_size = inside_extent.sizes();
    for (int a = 0; a < 3; ++a)
      EXPECT_GE(inside_size[a], 0.5 * box_size[a]) << "rig " << rig;
  }
  EXPECT_GE(bounded, 30);
}

}  // namespace
}  // namespace silnet::aggregator

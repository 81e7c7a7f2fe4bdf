// The voxel hull of a sphere seen by eight cameras on a ring, against analytic bounds.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/voxel_hull.h"

namespace silnet::aggregator {
namespace {

constexpr double kRingRadius = 4.5;  // camera distance D from the sphere centre, metres
constexpr double kRadius = 0.5;      // sphere radius r, metres
constexpr double kFocal = 686.0;     // pixels (50 degree horizontal field of view at 640 px)
constexpr int kCameras = 8;

const Eigen::Vector3d kSphereCentre(0.1, -0.05, 1.0);

// Eight cameras every 45 degrees on a horizontal ring through the sphere centre, all
// looking at it; the ring is turned so no camera looks along a grid axis.
std::vector<CameraModel> RingCameras(double k1 = 0.0) {
  std::vector<CameraModel> cameras;
  for (int i = 0; i < kCameras; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / kCameras + 0.1;
    CameraModel c;
    c.id = "ring" + std::to_string(i);
    c.width = 640;
    c.height = 480;
    c.K << kFocal, 0, 319.5, 0, kFocal, 239.5, 0, 0, 1;
    c.dist << k1, -0.25 * k1, 0, 0, 0;
    const Eigen::Vector3d centre =
        kSphereCentre + kRingRadius * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    c.R = LookAtRotation(centre, kSphereCentre, Eigen::Vector3d::UnitZ());
    c.t = -c.R * centre;
    cameras.push_back(c);
  }
  return cameras;
}

// Exact silhouette: a pixel is set iff the ray through its centre meets the sphere.
cv::Mat SphereMask(const CameraModel& camera) {
  cv::Mat mask = cv::Mat::zeros(camera.height, camera.width, CV_8UC1);
  const Eigen::Vector3d to_centre = camera.R * kSphereCentre + camera.t;  // camera frame
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = camera.PixelRay(Eigen::Vector2d(x, y)).normalized();
      if (ray.dot(to_centre) > 0 && ray.cross(to_centre).norm() <= kRadius) {
        mask.at<uint8_t>(y, x) = 255;
      }
    }
  }
  return mask;
}

// Bound on |X - S| over the intersection of the cameras' cones. A kept centre projects
// within half a pixel diagonal of a pixel centre whose ray meets the sphere, so it lies in
// the cone of half-angle a = asin(r / D) + atan(0.75 / f) about the camera's axis to S.
// Write X = S + v. For the camera whose axis d is closest to perpendicular to v's
// horizontal part (within 22.5 degrees, since cameras are every 45 degrees on a horizontal
// ring) |v . d| <= |v| sin(22.5), and the cone gives |v - (v.d) d| <= (D + v.d) tan(a).
// With c = cos(22.5), s = sin(22.5): |v| c <= (D + |v| s) tan(a), i.e.
// |v| <= D tan(a) / (c - s tan(a)). For D -> infinity this is r / cos(22.5): the octagon
// circumscribing the sphere's circle.
double ConeIntersectionRadius() {
  const double half_angle = std::asin(kRadius / kRingRadius) + std::atan(0.75 / kFocal);
  const double tan_a = std::tan(half_angle);
  const double c = std::cos(std::numbers::pi / 8), s = std::sin(std::numbers::pi / 8);
  return kRingRadius * tan_a / (c - s * tan_a);
}

struct SphereScene {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
};

SphereScene MakeSphereScene(double k1 = 0.0) {
  SphereScene scene;
  scene.cameras = RingCameras(k1);
  for (const CameraModel& c : scene.cameras)
    scene.masks.push_back(SphereMask(c));
  return scene;
}

TEST(SphereHullTest, ViewingConeBoundsContainTheSphereAndLieWithinTheConeBound) {
  const SphereScene scene = MakeSphereScene();
  const ViewingConeBounds bounds = ComputeViewingConeBounds(scene.cameras, scene.masks);
  ASSERT_TRUE(bounds.success) << bounds.reason;
  const double rho = ConeIntersectionRadius();
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(bounds.box.min()[a], kSphereCentre[a] - kRadius);
    EXPECT_GE(bounds.box.max()[a], kSphereCentre[a] + kRadius);
    // The rectangle cones are a little wider than the circular ones (corners).
    EXPECT_GE(bounds.box.min()[a], kSphereCentre[a] - rho * std::sqrt(2.0));
    EXPECT_LE(bounds.box.max()[a], kSphereCentre[a] + rho * std::sqrt(2.0));
  }
}

TEST(SphereHullTest, HullContainsTheSphereAndLiesInTheConeIntersection) {
  const SphereScene scene = MakeSphereScene();
  VoxelHullOptions options;
  options.voxel_size = 0.02;
  options.threads = 1;
  const VoxelHullResult hull = CarveVoxelHull(scene.cameras, scene.masks, options);
  ASSERT_TRUE(hull.success) << hull.reason;
  const VoxelGrid& grid = hull.grid;
  // One voxel is more than a pixel's footprint at the sphere's far side.
  ASSERT_GT(options.voxel_size, (kRingRadius + kRadius) / kFocal);
  const double rho = ConeIntersectionRadius();
  const double diagonal = std::sqrt(3.0) * options.voxel_size;
  size_t kept = 0, inner = 0, farthest_violations = 0, cone_violations = 0, inner_missed = 0;
  double farthest = 0.0;
  for (int k = 0; k < grid.dims[2]; ++k) {
    for (int j = 0; j < grid.dims[1]; ++j) {
      for (int i = 0; i < grid.dims[0]; ++i) {
        const Eigen::Vector3d x = grid.Center(i, j, k);
        const double distance = (x - kSphereCentre).norm();
        const bool occupied = grid.IsOccupied(i, j, k);
        if (distance <= kRadius - options.voxel_size) {
          ++inner;
          if (!occupied) ++inner_missed;
        }
        if (!occupied) continue;
        ++kept;
        farthest = std::max(farthest, distance);
        if (distance > rho + diagonal) ++farthest_violations;
        if (!VoxelCentreInHull(scene.cameras, scene.masks, x)) ++cone_violations;
      }
    }
  }
  EXPECT_GT(inner, 10000u);
  EXPECT_EQ(inner_missed, 0u);
  EXPECT_EQ(farthest_violations, 0u) << "farthest " << farthest << " bound " << rho + diagonal;
  EXPECT_EQ(cone_violations, 0u);
  // The hull is tight: its volume lies between the sphere's and the bound sphere's.
  const double volume = static_cast<double>(kept) * std::pow(options.voxel_size, 3);
  const double sphere_volume = 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  EXPECT_GT(volume, sphere_volume * 0.97);
  EXPECT_LT(volume, sphere_volume * std::pow(rho / kRadius, 3));
  RecordProperty("farthest_kept_centre_m", std::to_string(farthest));
  RecordProperty("cone_bound_m", std::to_string(rho));
  std::printf(
      "sphere hull: %zu voxels, volume %.4f m^3 (sphere %.4f), farthest %.4f m, bound "
      "%.4f m + diagonal %.4f m\n",
      kept, volume, sphere_volume, farthest, rho, diagonal);
}

TEST(SphereHullTest, OctreeEqualsTheVoxelByVoxelTestOnAnyThreadCount) {
  const SphereScene scene = MakeSphereScene();
  VoxelHullOptions options;
  options.voxel_size = 0.03;
  options.threads = 1;
  const VoxelHullResult one = CarveVoxelHull(scene.cameras, scene.masks, options);
  ASSERT_TRUE(one.success) << one.reason;
  size_t disagreements = 0;
  const VoxelGrid& grid = one.grid;
  for (int k = 0; k < grid.dims[2]; ++k) {
    for (int j = 0; j < grid.dims[1]; ++j) {
      for (int i = 0; i < grid.dims[0]; ++i) {
        if (grid.IsOccupied(i, j, k) !=
            VoxelCentreInHull(scene.cameras, scene.masks, grid.Center(i, j, k))) {
          ++disagreements;
        }
      }
    }
  }
  EXPECT_EQ(disagreements, 0u);
  EXPECT_LT(one.stats.voxels_tested, grid.size() / 4);  // the octree skipped most voxels
  for (int levels : {0, 2, 6}) {
    options.threads = 2;
    options.octree_levels = levels;
    const VoxelHullResult other = CarveVoxelHull(scene.cameras, scene.masks, options);
    ASSERT_TRUE(other.success);
    EXPECT_EQ(other.grid.occupied, one.grid.occupied) << "levels " << levels;
  }
}

TEST(SphereHullTest, DistortedCamerasStillContainTheSphere) {
  const SphereScene scene = MakeSphereScene(-0.12);
  VoxelHullOptions options;
  options.voxel_size = 0.02;
  const VoxelHullResult hull = CarveVoxelHull(scene.cameras, scene.masks, options);
  ASSERT_TRUE(hull.success) << hull.reason;
  size_t inner_missed = 0, disagreements = 0;
  const VoxelGrid& grid = hull.grid;
  for (int k = 0; k < grid.dims[2]; ++k) {
    for (int j = 0; j < grid.dims[1]; ++j) {
      for (int i = 0; i < grid.dims[0]; ++i) {
        const Eigen::Vector3d x = grid.Center(i, j, k);
        if ((x - kSphereCentre).norm() <= kRadius - options.voxel_size &&
            !grid.IsOccupied(i, j, k)) {
          ++inner_missed;
        }
        if (grid.IsOccupied(i, j, k) != VoxelCentreInHull(scene.cameras, scene.masks, x)) {
          ++disagreements;
        }
      }
    }
  }
  EXPECT_EQ(inner_missed, 0u);
  EXPECT_EQ(disagreements, 0u);  // the distortion margin was wide enough here
}

TEST(SphereHullTest, MeshIsClosedManifoldAndReprojectsOntoTheSilhouettes) {
  const SphereScene scene = MakeSphereScene();
  VoxelHullOptions options;
  options.voxel_size = 0.02;
  const VoxelHullResult hull = CarveVoxelHull(scene.cameras, scene.masks, options);
  ASSERT_TRUE(hull.success) << hull.reason;
  const TriangleMesh mesh = ExtractBoundaryMesh(hull.grid);
  const MeshCheck check = CheckClosedManifold(mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 2);  // one sphere-like surface
  for (const ViewReprojection& view : MeasureHullReprojection(mesh, scene.cameras, scene.masks)) {
    // A silhouette pixel can be missed only where the hull is tight in several views at once
    // (the sphere's poles, on every camera's rim), where the voxel holding the surface point
    // may have its centre carved: a few pixels.
    EXPECT_LE(view.missed_fraction, 0.005) << view.camera_id;
    // Spurious coverage: at most the voxels' half-width (plus the cone excess) around the
    // outline, i.e. a band of a few pixels.
    EXPECT_LT(view.spurious_fraction, 0.12) << view.camera_id;
  }
}

TEST(SphereHullTest, EmptySilhouetteIsReportedNotThrown) {
  SphereScene scene = MakeSphereScene();
  scene.masks[3].setTo(0);
  const VoxelHullResult hull = CarveVoxelHull(scene.cameras, scene.masks, VoxelHullOptions{});
  EXPECT_FALSE(hull.success);
  EXPECT_NE(hull.reason.find("ring3"), std::string::npos) << hull.reason;
  VoxelHullOptions bad;
  bad.voxel_size = 0;
  EXPECT_FALSE(CarveVoxelHull(scene.cameras, scene.masks, bad).success);
}

}  // namespace
}  // namespace silnet::aggregator

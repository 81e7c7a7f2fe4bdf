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
#include "tests/aggregator/hulls/sphere_scene.h"

namespace silnet::aggregator {
namespace {

using namespace hull_testing;
const Eigen::Vector3d kSphereCentre = SphereCentre();

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

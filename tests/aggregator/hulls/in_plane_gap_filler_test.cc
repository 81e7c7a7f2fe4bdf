#include "aggregator/hulls/in_plane_gap_filler.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"

namespace silnet::aggregator {
namespace {

constexpr double kSide = 0.1;

// A closed box of two voxels along x (its long sides have a vertex half-way), and for each
// vertex the box faces it lies on: planes 0-5 are x = min, x = max, y = min, ... z = max.
struct TwoVoxelBox {
  TriangleMesh mesh;
  std::vector<std::vector<int>> planes;

  TwoVoxelBox() {
    VoxelGrid grid = VoxelGrid::Empty(Eigen::Vector3d(0, 0, 1), kSide, {4, 3, 3});
    grid.occupied[grid.Index(1, 1, 1)] = 1;
    grid.occupied[grid.Index(2, 1, 1)] = 1;
    mesh = ExtractBoundaryMesh(grid);
    Eigen::Vector3f low = mesh.vertices.front(), high = low;
    for (const Eigen::Vector3f& x : mesh.vertices) {
      low = low.cwiseMin(x);
      high = high.cwiseMax(x);
    }
    for (const Eigen::Vector3f& x : mesh.vertices) {
      std::vector<int>& list = planes.emplace_back();
      for (int axis = 0; axis < 3; ++axis) {
        if (x[axis] == low[axis]) list.push_back(2 * axis);
        if (x[axis] == high[axis]) list.push_back(2 * axis + 1);
      }
      std::sort(list.begin(), list.end());
    }
  }

  // True if every vertex of triangle `t` lies on plane `plane`.
  bool OnPlane(const std::array<int32_t, 3>& t, int plane) const {
    return std::all_of(t.begin(), t.end(), [&](int32_t v) {
      const std::vector<int>& list = planes[static_cast<size_t>(v)];
      return std::find(list.begin(), list.end(), plane) != list.end();
    });
  }
};

TEST(InPlaneGapFillerTest, FillsAFaceLeftOutWithItsOwnArea) {
  TwoVoxelBox box;
  ASSERT_TRUE(CheckClosedManifold(box.mesh).closed_manifold);
  const double volume = MeshVolume(box.mesh);
  const size_t before = box.mesh.triangles.size();
  // The top (z = max) is a 1 x 2 rectangle with a vertex in the middle of each long side.
  std::erase_if(box.mesh.triangles, [&](const auto& t) { return box.OnPlane(t, 5); });
  ASSERT_EQ(box.mesh.triangles.size(), before - 4);
  ASSERT_FALSE(CheckClosedManifold(box.mesh).closed_manifold);

  const GapFilling filling = FillInPlaneGaps(box.planes, box.mesh);
  EXPECT_EQ(filling.loops, 1u);
  EXPECT_EQ(filling.filled, 1u);
  EXPECT_NEAR(filling.area, 2 * kSide * kSide, 1e-8);  // float vertices
  EXPECT_NEAR(filling.widest, 2 * (2 * kSide * kSide) / (6 * kSide), 1e-7);
  const MeshCheck check = CheckClosedManifold(box.mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 2);
  EXPECT_NEAR(MeshVolume(box.mesh), volume, 1e-8);  // in the plane, facing out
}

TEST(InPlaneGapFillerTest, FillsTwoGapsThatTouchAtAVertex) {
  TwoVoxelBox box;
  // Two top triangles with exactly one vertex in common: the boundary passes that vertex twice.
  std::vector<std::array<int32_t, 3>> top;
  for (const auto& t : box.mesh.triangles) {
    if (box.OnPlane(t, 5)) top.push_back(t);
  }
  const auto shared = [](const std::array<int32_t, 3>& x, const std::array<int32_t, 3>& y) {
    int count = 0;
    for (const int32_t v : x)
      count += std::count(y.begin(), y.end(), v) > 0 ? 1 : 0;
    return count;
  };
  std::pair<size_t, size_t> pair(0, 0);
  for (size_t i = 0; i < top.size(); ++i) {
    for (size_t j = i + 1; j < top.size(); ++j) {
      if (shared(top[i], top[j]) == 1) pair = {i, j};
    }
  }
  ASSERT_NE(pair.first, pair.second);
  std::erase_if(box.mesh.triangles,
                [&](const auto& t) { return t == top[pair.first] || t == top[pair.second]; });

  const GapFilling filling = FillInPlaneGaps(box.planes, box.mesh);
  EXPECT_EQ(filling.loops, 2u);
  EXPECT_EQ(filling.filled, 2u);
  const MeshCheck check = CheckClosedManifold(box.mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
}

TEST(InPlaneGapFillerTest, LeavesAGapAcrossTwoPlanesOpen) {
  TwoVoxelBox box;
  // One top triangle and a side triangle sharing one of its edges: their outline bends over
  // that edge, so no one plane holds it.
  const auto top = std::find_if(box.mesh.triangles.begin(), box.mesh.triangles.end(),
                                [&](const auto& t) { return box.OnPlane(t, 5); });
  ASSERT_NE(top, box.mesh.triangles.end());
  const std::array<int32_t, 3> removed = *top;
  box.mesh.triangles.erase(top);
  const auto side = std::find_if(
      box.mesh.triangles.begin(), box.mesh.triangles.end(), [&](const std::array<int32_t, 3>& t) {
        int shared = 0;
        for (const int32_t v : t)
          shared += std::count(removed.begin(), removed.end(), v) > 0 ? 1 : 0;
        return shared == 2 && !box.OnPlane(t, 5);
      });
  ASSERT_NE(side, box.mesh.triangles.end());
  box.mesh.triangles.erase(side);
  const size_t triangles = box.mesh.triangles.size();

  const GapFilling filling = FillInPlaneGaps(box.planes, box.mesh);
  EXPECT_EQ(filling.loops, 1u);
  EXPECT_EQ(filling.filled, 0u);
  EXPECT_EQ(box.mesh.triangles.size(), triangles);
  EXPECT_FALSE(CheckClosedManifold(box.mesh).closed_manifold);
}

}  // namespace
}  // namespace silnet::aggregator

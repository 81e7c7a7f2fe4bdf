#include "aggregator/hulls/mesh_topology.h"

#include <gtest/gtest.h>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/hulls/voxel_grid.h"

namespace silnet::aggregator {
namespace {

// The boundary of the occupied voxels of a 6^3 grid where `fill(i, j, k)` is true.
template <typename Fill>
TriangleMesh VoxelSolid(Fill fill) {
  VoxelGrid grid = VoxelGrid::Empty(Eigen::Vector3d(0, 0, 1), 0.1, {6, 6, 6});
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k)
        grid.occupied[grid.Index(i, j, k)] = fill(i, j, k) ? 1 : 0;
  return ExtractBoundaryMesh(grid);
}

TEST(MeshTopologyTest, SeparateBlocksAndARingAreToldApart) {
  // A 4x4x2 ring (the middle 2x2 column empty: one through-hole) and a separate small cube.
  const TriangleMesh mesh = VoxelSolid([](int i, int j, int k) {
    const bool ring = i < 4 && j < 4 && k < 2 && !(i >= 1 && i <= 2 && j >= 1 && j <= 2);
    const bool cube = i == 5 && j == 5 && k == 5;
    return ring || cube;
  });
  const std::vector<MeshComponent> pieces = MeshComponents(mesh);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(pieces[0].genus, 1);
  EXPECT_EQ(pieces[0].euler_characteristic, 0);
  EXPECT_EQ(pieces[1].genus, 0);
  EXPECT_EQ(pieces[1].triangles, 12u);
  EXPECT_EQ(pieces[1].vertices, 8u);
  EXPECT_GT(pieces[0].triangles, pieces[1].triangles);
}

TEST(MeshTopologyTest, TwoHolesAreGenusTwoAndBadTrianglesAreIgnored) {
  // A 5x3x1 slab with two separate holes.
  TriangleMesh mesh = VoxelSolid([](int i, int j, int k) {
    return i < 5 && j < 3 && k == 0 && !(j == 1 && (i == 1 || i == 3));
  });
  mesh.triangles.push_back({0, 0, 1});
  mesh.triangles.push_back({0, 1, static_cast<int32_t>(mesh.vertices.size())});
  const std::vector<MeshComponent> pieces = MeshComponents(mesh);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].genus, 2);
  EXPECT_TRUE(MeshComponents(TriangleMesh{}).empty());
}

}  // namespace
}  // namespace silnet::aggregator

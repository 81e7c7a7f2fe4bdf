#include "aggregator/hulls/boundary_mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <utility>

#include "aggregator/hulls/mesh_check.h"

namespace silnet::aggregator {
namespace {

// Volume enclosed by a closed, outward-oriented mesh (divergence theorem).
double EnclosedVolume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[static_cast<size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[static_cast<size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[static_cast<size_t>(t[2])].cast<double>();
    volume += a.dot(b.cross(c)) / 6.0;
  }
  return volume;
}

VoxelGrid SmallGrid(int n) {
  return VoxelGrid::Empty(Eigen::Vector3d(-0.3, 0.2, 1.0), 0.05, {n, n, n});
}

TEST(BoundaryMeshTest, SingleVoxelIsACube) {
  VoxelGrid grid = SmallGrid(3);
  grid.occupied[grid.Index(1, 1, 1)] = 1;
  const TriangleMesh mesh = ExtractBoundaryMesh(grid);
  EXPECT_EQ(mesh.vertices.size(), 8u);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  const MeshCheck check = CheckClosedManifold(mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 2);
  EXPECT_NEAR(EnclosedVolume(mesh), 0.05 * 0.05 * 0.05, 1e-9);
}

TEST(BoundaryMeshTest, VoxelsTouchingAlongAnEdgeOrACornerStaySeparate) {
  // Edge contact: two cubes, two spheres' worth of topology (chi = 4).
  VoxelGrid edge = SmallGrid(3);
  edge.occupied[edge.Index(0, 0, 1)] = 1;
  edge.occupied[edge.Index(1, 1, 1)] = 1;
  MeshCheck check = CheckClosedManifold(ExtractBoundaryMesh(edge));
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 4);
  // Corner contact.
  VoxelGrid corner = SmallGrid(3);
  corner.occupied[corner.Index(0, 0, 0)] = 1;
  corner.occupied[corner.Index(1, 1, 1)] = 1;
  check = CheckClosedManifold(ExtractBoundaryMesh(corner));
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 4);
}

TEST(BoundaryMeshTest, EdgeContactJoinedAboveAndBelowIsATorus) {
  // Two columns touching along an edge in the middle layer and joined by full layers above
  // and below: the pinched edge's ends lie on one sheet, which needs midpoint vertices.
  VoxelGrid grid = SmallGrid(4);
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      grid.occupied[grid.Index(i, j, 0)] = 1;
      grid.occupied[grid.Index(i, j, 2)] = 1;
    }
  }
  grid.occupied[grid.Index(0, 0, 1)] = 1;
  grid.occupied[grid.Index(1, 1, 1)] = 1;
  const TriangleMesh mesh = ExtractBoundaryMesh(grid);
  const MeshCheck check = CheckClosedManifold(mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  // A solid with one through-hole (the two columns kept apart): genus 1, chi = 0.
  EXPECT_EQ(check.euler_characteristic, 0);
  EXPECT_NEAR(EnclosedVolume(mesh), 10 * std::pow(0.05, 3), 1e-9);
}

TEST(BoundaryMeshTest, RandomOccupancyGivesClosedManifoldOfTheRightVolume) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    std::mt19937_64 rng(seed);
    std::bernoulli_distribution fill(seed % 2 ? 0.5 : 0.3);
    VoxelGrid grid = SmallGrid(10);
    for (uint8_t& v : grid.occupied)
      v = fill(rng) ? 1 : 0;
    const TriangleMesh mesh = ExtractBoundaryMesh(grid);
    const MeshCheck check = CheckClosedManifold(mesh);
    ASSERT_TRUE(check.closed_manifold) << "seed " << seed << ": " << check.reason;
    const double expected = static_cast<double>(grid.CountOccupied()) * std::pow(0.05, 3);
    EXPECT_NEAR(EnclosedVolume(mesh), expected, 1e-4 * expected) << "seed " << seed;
  }
}

TEST(BoundaryMeshTest, EmptyGridGivesEmptyMesh) {
  const TriangleMesh mesh = ExtractBoundaryMesh(SmallGrid(4));
  EXPECT_TRUE(mesh.vertices.empty());
  EXPECT_TRUE(mesh.triangles.empty());
}

TEST(MeshCheckTest, FindsOpenEdgesAndMisorientedTriangles) {
  VoxelGrid grid = SmallGrid(3);
  grid.occupied[grid.Index(1, 1, 1)] = 1;
  TriangleMesh open = ExtractBoundaryMesh(grid);
  open.triangles.pop_back();
  MeshCheck check = CheckClosedManifold(open);
  EXPECT_FALSE(check.closed_manifold);
  EXPECT_EQ(check.open_edges, 3u);

  TriangleMesh flipped = ExtractBoundaryMesh(grid);
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  check = CheckClosedManifold(flipped);
  EXPECT_FALSE(check.closed_manifold);
  EXPECT_EQ(check.misoriented_edges, 3u);

  TriangleMesh doubled = ExtractBoundaryMesh(grid);
  const auto extra = doubled.triangles;
  for (auto t : extra) {
    std::swap(t[1], t[2]);
    doubled.triangles.push_back(t);
  }
  check = CheckClosedManifold(doubled);
  EXPECT_FALSE(check.closed_manifold);
  EXPECT_GT(check.non_manifold_edges, 0u);
}

TEST(MeshCheckTest, EndsAFanWalkThatNeverReturns) {
  // Around vertex 0 the links are 1 -> 2, 2 -> 3 and 3 -> 2: a walk from 1 circles between
  // 2 and 3 for ever unless it is cut off.
  TriangleMesh mesh;
  mesh.vertices = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0),
                   Eigen::Vector3f(0, 0, 1)};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 2}};
  const MeshCheck check = CheckClosedManifold(mesh);
  EXPECT_FALSE(check.closed_manifold);
  EXPECT_GE(check.non_manifold_vertices, 1u);
}

TEST(MeshCheckTest, FindsVerticesJoiningTwoSheets) {
  // Two tetrahedra sharing one vertex: every edge is fine, the shared vertex is not.
  TriangleMesh mesh;
  mesh.vertices = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0),  Eigen::Vector3f(0, 1, 0),
                   Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(-1, 0, 0), Eigen::Vector3f(0, -1, 0),
                   Eigen::Vector3f(0, 0, -1)};
  for (int32_t b : {0, 3}) {
    const int32_t o = 0, x = b + 1, y = b + 2, z = b + 3;
    mesh.triangles.push_back({o, y, x});
    mesh.triangles.push_back({o, x, z});
    mesh.triangles.push_back({o, z, y});
    mesh.triangles.push_back({x, y, z});
  }
  const MeshCheck check = CheckClosedManifold(mesh);
  EXPECT_EQ(check.open_edges, 0u);
  EXPECT_EQ(check.non_manifold_edges, 0u);
  EXPECT_EQ(check.misoriented_edges, 0u);
  EXPECT_EQ(check.non_manifold_vertices, 1u);
  EXPECT_FALSE(check.closed_manifold);
}

}  // namespace
}  // namespace silnet::aggregator

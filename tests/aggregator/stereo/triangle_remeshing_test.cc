// Red-green subdivision of triangle meshes (the local refinement's remeshing, thesis 7.4.3):
// a closed, oriented manifold stays one, the shape (and so the volume) does not change, the
// picked edges end up short, and the triangle cap is honoured.

#include "aggregator/stereo/triangle_remeshing.h"

#include <gtest/gtest.h>

#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "tests/aggregator/stereo/test_spheres.h"

namespace silnet::aggregator {
namespace {

using testing::Icosphere;

double EdgeLength(const TriangleMesh& mesh, int32_t a, int32_t b) {
  return (mesh.vertices[static_cast<size_t>(a)] - mesh.vertices[static_cast<size_t>(b)]).norm();
}

TEST(TriangleRemeshingTest, SplittingEveryEdgeSplitsEveryTriangleRed) {
  TriangleMesh mesh = Icosphere(Eigen::Vector3d::Zero(), 1.0, 0);
  const double volume = MeshVolume(mesh);
  SubdivisionStats stats;
  std::vector<std::array<int32_t, 2>> parents;
  ASSERT_TRUE(SubdivideLongEdges(
      &mesh, [](int32_t, int32_t) { return true; }, 1000, &stats, &parents));
  EXPECT_EQ(stats.edges_split, 30u);
  EXPECT_EQ(stats.closure, 0u);
  EXPECT_EQ(stats.red, 20u);
  EXPECT_EQ(stats.green, 0u);
  EXPECT_EQ(mesh.triangles.size(), 80u);
  EXPECT_EQ(mesh.vertices.size(), 42u);
  ASSERT_EQ(parents.size(), 30u);
  for (size_t i = 0; i < parents.size(); ++i) {
    const Eigen::Vector3f middle = 0.5f * (mesh.vertices[static_cast<size_t>(parents[i][0])] +
                                           mesh.vertices[static_cast<size_t>(parents[i][1])]);
    EXPECT_LT((mesh.vertices[12 + i] - middle).norm(), 1e-6f);
  }
  EXPECT_TRUE(CheckClosedManifold(mesh).closed_manifold);
  EXPECT_NEAR(MeshVolume(mesh), volume, 1e-6);
}

// Edges are picked by their midpoints on one side of a plane only, round after round: red and
// green triangles meet along the border, triangles with two picked edges are closed to red,
// the mesh stays closed and manifold with the same volume, and every picked edge ends up
// shorter than the bound.
TEST(TriangleRemeshingTest, SplittingLongEdgesOnOneSideKeepsAClosedManifold) {
  TriangleMesh mesh = Icosphere(Eigen::Vector3d(0.2, -0.1, 0.3), 1.0, 2);
  const double volume = MeshVolume(mesh);
  const double bound = 0.08;
  const auto picked = [&](int32_t a, int32_t b) {
    return mesh.vertices[static_cast<size_t>(a)].z() + mesh.vertices[static_cast<size_t>(b)].z() >
           0.6f;
  };
  size_t red = 0, green = 0, closure = 0;
  for (int round = 0; round < 6; ++round) {
    SubdivisionStats stats;
    const bool changed = SubdivideLongEdges(
        &mesh, [&](int32_t a, int32_t b) { return picked(a, b) && EdgeLength(mesh, a, b) > bound; },
        1'000'000, &stats);
    red += stats.red;
    green += stats.green;
    closure += stats.closure;
    if (!changed) break;
    const MeshCheck check = CheckClosedManifold(mesh);
    ASSERT_TRUE(check.closed_manifold) << "round " << round << ": " << check.reason;
  }
  EXPECT_GT(red, 0u);
  EXPECT_GT(green, 0u);
  EXPECT_GT(closure, 0u);
  EXPECT_NEAR(MeshVolume(mesh), volume, 1e-6);
  for (const auto& t : mesh.triangles)
    for (size_t e = 0; e < 3; ++e)
      if (picked(t[e], t[(e + 1) % 3])) {
        EXPECT_LE(EdgeLength(mesh, t[e], t[(e + 1) % 3]), bound);
      }
}

TEST(TriangleRemeshingTest, NothingChangesAboveTheTriangleCapOrWithoutPickedEdges) {
  TriangleMesh mesh = Icosphere(Eigen::Vector3d::Zero(), 1.0, 1);
  const TriangleMesh before = mesh;
  EXPECT_FALSE(SubdivideLongEdges(
      &mesh, [](int32_t, int32_t) { return true; }, 319));
  EXPECT_FALSE(SubdivideLongEdges(
      &mesh, [](int32_t, int32_t) { return false; }, 1000));
  EXPECT_EQ(mesh.triangles, before.triangles);
  EXPECT_EQ(mesh.vertices.size(), before.vertices.size());
  EXPECT_TRUE(SubdivideLongEdges(
      &mesh, [](int32_t, int32_t) { return true; }, 320));
  EXPECT_EQ(mesh.triangles.size(), 320u);
}

}  // namespace
}  // namespace silnet::aggregator

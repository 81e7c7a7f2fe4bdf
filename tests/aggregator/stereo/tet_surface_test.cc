// Surfaces of sets of tetrahedra (made manifold where they pinch) and point location.

#include "aggregator/stereo/tet_surface.h"

#include <gtest/gtest.h>

#include <random>

#include "aggregator/hulls/mesh_check.h"
#include "aggregator/stereo/tet_point_locator.h"

namespace silnet::aggregator {
namespace {

Eigen::Vector3d Centroid(const TetMesh& mesh, const Tetrahedron& t) {
  return (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]] + mesh.vertices[t[3]]) /
         4;
}

TEST(TetSurfaceTest, TwoBlocksTouchingAtAnEdgeAreJoinedIntoAManifold) {
  const TetMesh mesh =
      BuildBccLattice(WorldBox(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), 0.125);
  // Two blocks of cells meeting along the line x = y = 0.5: the boundary pinches there.
  std::vector<uint8_t> interior(mesh.tetrahedra.size(), 0);
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    const Eigen::Vector3d c = Centroid(mesh, mesh.tetrahedra[t]);
    const bool low = c.x() > 0.25 && c.x() < 0.5 && c.y() > 0.25 && c.y() < 0.5;
    const bool high = c.x() > 0.5 && c.x() < 0.75 && c.y() > 0.5 && c.y() < 0.75;
    if ((low || high) && c.z() > 0.25 && c.z() < 0.75) interior[t] = 1;
  }
  const std::vector<CellFace> faces = SortedCellFaces(mesh);
  EXPECT_FALSE(CheckClosedManifold(InteriorBoundary(mesh, faces, interior)).closed_manifold);
  const size_t added = RepairPinches(mesh, faces, &interior);
  EXPECT_GT(added, 0u);
  const MeshCheck check = CheckClosedManifold(InteriorBoundary(mesh, faces, interior));
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  // The smoothed surface stays closed and manifold, every vertex within its bound.
  TetSurfaceOptions options;
  options.max_vertex_shift = 0.03;
  const TriangleMesh smooth = ExtractTetSurface(mesh, faces, interior, options, {});
  EXPECT_TRUE(CheckClosedManifold(smooth).closed_manifold);
}

TEST(TetSurfaceTest, PinchRepairKeepsOutOfAvoidedCellsWhereItCan) {
  const TetMesh mesh =
      BuildBccLattice(WorldBox(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), 0.125);
  // The blocks of the test above; the cells on one side of the pinch line (x < 0.5 < y) are
  // to be avoided, the other side (y < 0.5 < x) can close it.
  std::vector<uint8_t> interior(mesh.tetrahedra.size(), 0), avoid(mesh.tetrahedra.size(), 0);
  for (size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    const Eigen::Vector3d c = Centroid(mesh, mesh.tetrahedra[t]);
    const bool low = c.x() > 0.25 && c.x() < 0.5 && c.y() > 0.25 && c.y() < 0.5;
    const bool high = c.x() > 0.5 && c.x() < 0.75 && c.y() > 0.5 && c.y() < 0.75;
    if ((low || high) && c.z() > 0.25 && c.z() < 0.75) interior[t] = 1;
    avoid[t] = c.x() < 0.5 && c.y() > 0.5 ? 1 : 0;
  }
  const std::vector<CellFace> faces = SortedCellFaces(mesh);
  // Unconstrained, the repair takes cells from both sides.
  std::vector<uint8_t> free_repair = interior;
  RepairPinches(mesh, faces, &free_repair);
  size_t taken = 0;
  for (size_t t = 0; t < avoid.size(); ++t)
    taken += avoid[t] && free_repair[t] ? 1 : 0;
  EXPECT_GT(taken, 0u);
  EXPECT_GT(RepairPinches(mesh, faces, &interior, avoid), 0u);
  const MeshCheck check = CheckClosedManifold(InteriorBoundary(mesh, faces, interior));
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  for (size_t t = 0; t < interior.size(); ++t) {
    if (avoid[t]) {
      EXPECT_FALSE(interior[t]) << t;
    }
  }
}

TEST(TetPointLocatorTest, FindsTheTetrahedronHoldingEachPoint) {
  const WorldBox box(Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 0.5, 0.75));
  const TetMesh mesh = BuildBccLattice(box, 0.125);
  const TetPointLocator locator(mesh, 0.2);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d p =
        box.min() + Eigen::Vector3d(u(random), u(random), u(random)).cwiseProduct(box.sizes());
    const int32_t t = locator.Locate(p);
    ASSERT_GE(t, 0);
    const Tetrahedron& tet = mesh.tetrahedra[static_cast<size_t>(t)];
    const auto& v = mesh.vertices;
    for (int c = 0; c < 4; ++c) {
      std::array<Eigen::Vector3d, 4> corners{v[tet[0]], v[tet[1]], v[tet[2]], v[tet[3]]};
      corners[static_cast<size_t>(c)] = p;
      EXPECT_GE(SignedVolume6(corners[0], corners[1], corners[2], corners[3]), -1e-12);
    }
  }
  EXPECT_EQ(locator.Locate(Eigen::Vector3d(5, 5, 5)), -1);
}

}  // namespace
}  // namespace silnet::aggregator

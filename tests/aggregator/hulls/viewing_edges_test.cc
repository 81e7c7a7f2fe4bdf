// The viewing edges computed once per contour vertex (aggregator/hulls/viewing_edges.h) against
// the polyhedral hull, which finds the same vertices face by face: every end of a viewing edge
// is a vertex of the hull on the same three cone faces at the same place, and their numbers
// agree, on the analytic sphere ring and on EPVH's alien set.

#include "aggregator/hulls/viewing_edges.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <map>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/real_datasets.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "tests/aggregator/hulls/sphere_scene.h"
#include "tests/support/real_data.h"

namespace silnet::aggregator {
namespace {

using PlaneTriple = std::array<int, 3>;

PlaneTriple Sorted(int a, int b, int c) {
  PlaneTriple t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

// Checks the viewing edges of `cameras`' silhouettes in `masks` against their polyhedral hull.
void ExpectEdgesAreTheHullsOwn(const std::vector<CameraModel>& cameras,
                               const std::vector<cv::Mat>& masks) {
  std::vector<SilhouetteContours> contours;
  for (const cv::Mat& mask : masks)
    contours.push_back(ExtractContours(mask, ContourOptions{}));
  const ViewingConeBounds bounds = ComputeViewingConeBounds(cameras, masks);
  ASSERT_TRUE(bounds.success) << bounds.reason;
  WorldBox box = bounds.box;
  const Eigen::Vector3d pad = 0.05 * box.sizes();
  box.min() -= pad;
  box.max() += pad;

  PolyhedralHullOptions options;
  options.keep_provenance = true;
  const PolyhedralHullResult hull = ComputePolyhedralHull(cameras, contours, box, options);
  ASSERT_TRUE(hull.success) << hull.reason;
  // Both from the plain contours' planes.
  ASSERT_FALSE(hull.stats.contours_perturbed);
  const ConePlaneSet set(cameras, contours, box);
  ASSERT_EQ(hull.provenance.planes.size(), set.Planes().size());

  std::map<PlaneTriple, int> hull_vertex;
  for (size_t v = 0; v < hull.provenance.vertex_planes.size(); ++v) {
    const std::vector<int>& planes = hull.provenance.vertex_planes[v];
    if (planes.size() == 3)
      hull_vertex[Sorted(planes[0], planes[1], planes[2])] = static_cast<int>(v);
  }

  const std::vector<ViewingEdge> edges = ComputeViewingEdges(cameras, set, box, 1);
  EXPECT_EQ(2 * edges.size(), hull.stats.viewing_edge_vertices);
  const double tolerance = 1e-6 * box.sizes().norm();  // the mesh holds floats
  size_t matched = 0;
  double worst = 0;
  for (const ViewingEdge& edge : edges) {
    ASSERT_LT(edge.near, edge.far);
    const int previous = set.Plane(edge.plane).prev;
    for (const auto& [t, bound] :
         {std::pair{edge.near, edge.near_plane}, {edge.far, edge.far_plane}}) {
      ASSERT_GE(bound, 0) << "an edge ends at the bounds box";
      EXPECT_NE(set.Plane(bound).view, edge.view);
      const auto found = hull_vertex.find(Sorted(previous, edge.plane, bound));
      if (found == hull_vertex.end()) {
        ADD_FAILURE() << "no hull vertex on planes " << previous << ", " << edge.plane << ", "
                      << bound;
        continue;
      }
      const double distance =
          (ViewingEdgePoint(cameras, set, edge, t) -
           hull.mesh.vertices[static_cast<size_t>(found->second)].cast<double>())
              .norm();
      worst = std::max(worst, distance);
      ++matched;
    }
  }
  EXPECT_EQ(matched, hull.stats.viewing_edge_vertices);
  EXPECT_LE(worst, tolerance);
  std::printf("  %zu views: %zu viewing edges, every end a hull vertex within %.2g (box %.3g)\n",
              cameras.size(), edges.size(), worst, box.sizes().norm());

  // The same edges on two threads.
  const std::vector<ViewingEdge> threaded = ComputeViewingEdges(cameras, set, box, 2);
  ASSERT_EQ(threaded.size(), edges.size());
  for (size_t k = 0; k < edges.size(); ++k) {
    EXPECT_EQ(threaded[k].plane, edges[k].plane);
    EXPECT_EQ(threaded[k].near, edges[k].near);
    EXPECT_EQ(threaded[k].far_plane, edges[k].far_plane);
  }
}

TEST(ViewingEdgesTest, EndsAreTheHullsVerticesOnTheSphereRing) {
  const hull_testing::SphereScene scene = hull_testing::MakeSphereScene(0.0, true);
  ExpectEdgesAreTheHullsOwn(scene.cameras, scene.masks);
}

TEST(ViewingEdgesTest, EndsAreTheHullsVerticesOnEpvhAlien) {
  const std::filesystem::path folder =
      std::filesystem::path(SILNET_SHARED_DATA_DIR) / "epvh-alien-24cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  const RealCapture alien = LoadEpvhAlien(folder, 8);
  ExpectEdgesAreTheHullsOwn(alien.cameras, alien.masks);
}

// Cones that do not all meet have no viewing edges: the last view sees a sphere 1 m above
// the one the others see (its cone passes 0.7 m above their intersection).
TEST(ViewingEdgesTest, NoEdgesWhereTheConesDoNotAllMeet) {
  hull_testing::SphereScene scene = hull_testing::MakeSphereScene(0.0, true);
  scene.masks.back() = hull_testing::SphereMask(
      scene.cameras.back(), hull_testing::SphereCentre() + Eigen::Vector3d(0, 0, 1.0), 0.3);
  std::vector<SilhouetteContours> contours;
  for (const cv::Mat& mask : scene.masks)
    contours.push_back(ExtractContours(mask, ContourOptions{}));
  const WorldBox box(hull_testing::SphereCentre() - Eigen::Vector3d::Constant(3),
                     hull_testing::SphereCentre() + Eigen::Vector3d::Constant(3));
  const ConePlaneSet set(scene.cameras, contours, box);
  EXPECT_TRUE(ComputeViewingEdges(scene.cameras, set, box).empty());
}

}  // namespace
}  // namespace silnet::aggregator

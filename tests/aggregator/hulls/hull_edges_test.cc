// The viewing edges computed once per contour vertex (aggregator/hulls/viewing_edges.h) and
// the edges traced from them (hull_edges.h) against the polyhedral hull, which finds the same
// vertices face by face: every end of a viewing edge is a vertex of the hull on the same three
// cone faces at the same place, the traced vertices are exactly the hull's, and the traced
// edges exactly its mesh edges along two cone faces (the same graph traced on two threads),
// on the analytic sphere ring and on EPVH's alien set.

#include "aggregator/hulls/hull_edges.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <iterator>
#include <map>
#include <set>
#include <utility>

#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/real_datasets.h"
#include "aggregator/hulls/traced_hull_mesh.h"
#include "aggregator/hulls/viewing_cone_bounds.h"
#include "aggregator/hulls/viewing_edges.h"
#include "tests/aggregator/hulls/sphere_scene.h"
#include "tests/support/real_data.h"

namespace silnet::aggregator {
namespace {

// Checks the viewing edges of `cameras`' silhouettes in `masks`, and the edges traced from
// them, against their polyhedral hull.
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
  options.trace_edges = false;  // the face-by-face sweeps: the reference
  const PolyhedralHullResult hull = ComputePolyhedralHull(cameras, contours, box, options);
  ASSERT_TRUE(hull.success) << hull.reason;
  ASSERT_FALSE(hull.stats.traced_edges);
  // Both from the plain contours' planes.
  ASSERT_FALSE(hull.stats.contours_perturbed);
  const ConePlaneSet set(cameras, contours, box);
  ASSERT_EQ(hull.provenance.planes.size(), set.Planes().size());

  std::map<PlaneTriple, int> hull_vertex;
  for (size_t v = 0; v < hull.provenance.vertex_planes.size(); ++v) {
    const std::vector<int>& planes = hull.provenance.vertex_planes[v];
    if (planes.size() == 3)
      hull_vertex[SortedPlanes(planes[0], planes[1], planes[2])] = static_cast<int>(v);
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
      const auto found = hull_vertex.find(SortedPlanes(previous, edge.plane, bound));
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

  // The edges traced from them: the hull's vertices and its edges along two cone faces.
  const HullEdgeGraph graph = TraceHullEdges(cameras, set, box, edges);
  EXPECT_EQ(graph.open_ends, 0u);
  // The same graph, in the same order, on two threads.
  const HullEdgeGraph parallel = TraceHullEdges(cameras, set, box, edges, 2);
  ASSERT_EQ(parallel.vertices.size(), graph.vertices.size());
  ASSERT_EQ(parallel.edges.size(), graph.edges.size());
  EXPECT_EQ(parallel.traced, graph.traced);
  for (size_t v = 0; v < graph.vertices.size(); ++v) {
    EXPECT_EQ(parallel.vertices[v].planes, graph.vertices[v].planes);
    EXPECT_EQ(parallel.vertices[v].position, graph.vertices[v].position);
  }
  for (size_t e = 0; e < graph.edges.size(); ++e) {
    const HullEdge& x = graph.edges[e];
    const HullEdge& y = parallel.edges[e];
    EXPECT_TRUE(x.a == y.a && x.b == y.b && x.from == y.from && x.to == y.to) << "edge " << e;
  }
  EXPECT_EQ(graph.vertices.size(), hull.stats.viewing_edge_vertices + hull.stats.triple_points);
  EXPECT_EQ(graph.vertices.size(), hull_vertex.size());
  double worst_vertex = 0;
  for (const HullEdgeVertex& vertex : graph.vertices) {
    const auto found = hull_vertex.find(vertex.planes);
    if (found == hull_vertex.end()) {
      ADD_FAILURE() << "traced vertex on planes " << vertex.planes[0] << ", " << vertex.planes[1]
                    << ", " << vertex.planes[2] << " is not the hull's";
      continue;
    }
    worst_vertex = std::max(
        worst_vertex,
        (vertex.position - hull.mesh.vertices[static_cast<size_t>(found->second)].cast<double>())
            .norm());
  }
  EXPECT_LE(worst_vertex, tolerance);
  // The mesh's edges whose ends share two cone planes are the hull's own (the other mesh
  // edges cut across a face).
  std::set<std::pair<PlaneTriple, PlaneTriple>> mesh_edges, traced_edges;
  for (const auto& triangle : hull.mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::vector<int>& p = hull.provenance.vertex_planes[static_cast<size_t>(triangle[k])];
      const std::vector<int>& q =
          hull.provenance.vertex_planes[static_cast<size_t>(triangle[(k + 1) % 3])];
      std::vector<int> shared;
      std::set_intersection(p.begin(), p.end(), q.begin(), q.end(), std::back_inserter(shared));
      if (p.size() != 3 || q.size() != 3 || shared.size() != 2) continue;
      const PlaneTriple u = SortedPlanes(p[0], p[1], p[2]), w = SortedPlanes(q[0], q[1], q[2]);
      mesh_edges.insert({std::min(u, w), std::max(u, w)});
    }
  }
  for (const HullEdge& edge : graph.edges) {
    const PlaneTriple& u = graph.vertices[static_cast<size_t>(edge.from)].planes;
    const PlaneTriple& w = graph.vertices[static_cast<size_t>(edge.to)].planes;
    traced_edges.insert({std::min(u, w), std::max(u, w)});
  }
  EXPECT_EQ(traced_edges.size(), graph.edges.size()) << "an edge traced twice";
  EXPECT_EQ(traced_edges, mesh_edges);
  std::printf("  traced %zu edges: %zu vertices, %zu edges (%zu viewing edges), worst %.2g\n",
              graph.traced, graph.vertices.size(), graph.edges.size(), graph.viewing_edges,
              worst_vertex);

  // Their faces' loops triangulated: the hull's solid, closed, with as many triangles.
  const TracedHullMesh traced = AssembleTracedHull(set, graph);
  ASSERT_TRUE(traced.success) << traced.reason;
  const MeshCheck check = CheckClosedManifold(traced.mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(traced.mesh.triangles.size(), hull.mesh.triangles.size());
  EXPECT_EQ(traced.faces, hull.stats.hull_faces);
  const double volume = MeshVolume(hull.mesh);
  EXPECT_NEAR(MeshVolume(traced.mesh), volume, 1e-6 * volume);
  std::printf("  assembled: %zu faces, %zu loops, %zu triangles, volume %.6g (hull %.6g)\n",
              traced.faces, traced.loops, traced.mesh.triangles.size(), MeshVolume(traced.mesh),
              volume);

  // The same edges on two threads.
  const std::vector<ViewingEdge> threaded = ComputeViewingEdges(cameras, set, box, 2);
  ASSERT_EQ(threaded.size(), edges.size());
  for (size_t k = 0; k < edges.size(); ++k) {
    EXPECT_EQ(threaded[k].plane, edges[k].plane);
    EXPECT_EQ(threaded[k].near, edges[k].near);
    EXPECT_EQ(threaded[k].far_plane, edges[k].far_plane);
  }
}

TEST(HullEdgesTest, TheHullsOwnVerticesAndEdgesOnTheSphereRing) {
  const hull_testing::SphereScene scene = hull_testing::MakeSphereScene(0.0, true);
  ExpectEdgesAreTheHullsOwn(scene.cameras, scene.masks);
}

TEST(HullEdgesTest, TheHullsOwnVerticesAndEdgesOnEpvhAlien) {
  const std::filesystem::path folder =
      std::filesystem::path(SILNET_SHARED_DATA_DIR) / "epvh-alien-24cam";
  SILNET_REQUIRE_REAL_DATA(folder);
  const RealCapture alien = LoadEpvhAlien(folder, 8);
  ExpectEdgesAreTheHullsOwn(alien.cameras, alien.masks);
}

// Cones that do not all meet have no viewing edges: the last view sees a sphere 1 m above
// the one the others see (its cone passes 0.7 m above their intersection).
TEST(HullEdgesTest, NoEdgesWhereTheConesDoNotAllMeet) {
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

// The exact polyhedral hull against analytic bounds on a sphere and against the voxel hull.

#include "aggregator/hulls/polyhedral_hull.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/mesh_measure.h"
#include "aggregator/hulls/voxel_hull.h"
#include "shared/silhouette/silhouette_contour.h"
#include "tests/aggregator/hulls/hull_comparison.h"
#include "tests/aggregator/hulls/sphere_scene.h"

namespace silnet::aggregator {
namespace {

using namespace hull_testing;

TEST(PolyhedralHullTest, SphereHullIsClosedAndLiesBetweenTheSphereAndTheConeBound) {
  const SphereScene scene = MakeSphereScene(0.0, true);
  const PolyhedralHullResult hull = ComputePolyhedralHull(scene.cameras, scene.masks);
  ASSERT_TRUE(hull.success) << hull.reason;
  const MeshCheck check = CheckClosedManifold(hull.mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 2);
  EXPECT_GT(hull.stats.triple_points, 20u);
  EXPECT_GT(hull.stats.viewing_edge_vertices, 100u);

  // Vertices lie on the cones: outside the sphere (up to the contour's pixel and the
  // simplification tolerance, 2 px at the far side) and inside the bound of the cone
  // intersection (the bound allows 0.75 px; the contour adds up to 1 px more, the jittered
  // ring up to 4 cm of height and 2 cm of aim).
  const double pixel = (kRingRadius + kRadius) / kFocal;
  const double rho = ConeIntersectionRadius() + 2 * pixel + 0.01;
  double nearest = 1e9, farthest = 0;
  for (const Eigen::Vector3f& x : hull.mesh.vertices) {
    const double d = (x.cast<double>() - SphereCentre()).norm();
    nearest = std::min(nearest, d);
    farthest = std::max(farthest, d);
  }
  EXPECT_GE(nearest, kRadius - 2 * pixel);
  EXPECT_LE(farthest, rho);
  const double volume = MeshVolume(hull.mesh);
  const double sphere_volume = 4.0 / 3.0 * std::numbers::pi * std::pow(kRadius, 3);
  EXPECT_GT(volume, sphere_volume * std::pow(1 - 2 * pixel / kRadius, 3));
  EXPECT_LT(volume, sphere_volume * std::pow(rho / kRadius, 3));
  std::printf(
      "polyhedral sphere hull: %zu vertices, %zu triangles, %zu of %zu cone faces on the hull, "
      "%zu triple points, %zu viewing-edge vertices, %zu edge points; |X - S| in [%.4f, %.4f] "
      "m (sphere %.2f, bound %.4f); volume %.4f m^3 (sphere %.4f)\n",
      hull.mesh.vertices.size(), hull.mesh.triangles.size(), hull.stats.hull_faces,
      hull.stats.cone_faces, hull.stats.triple_points, hull.stats.viewing_edge_vertices,
      hull.stats.edge_points, nearest, farthest, kRadius, rho, volume, sphere_volume);
}

// Faces triangulated as the polygons they are and faces assembled from their sweeps'
// trapezoids with the cuts give the same solid; the polygons add no vertex of their own.
TEST(PolyhedralHullTest, FacesAsPolygonsAreTheSameSolidWithoutExtraPoints) {
  const SphereScene scene = MakeSphereScene(0.0, true);
  PolyhedralHullOptions with_cuts;
  with_cuts.faces_as_polygons = false;
  const PolyhedralHullResult polygons = ComputePolyhedralHull(scene.cameras, scene.masks);
  const PolyhedralHullResult cuts = ComputePolyhedralHull(scene.cameras, scene.masks, with_cuts);
  ASSERT_TRUE(polygons.success) << polygons.reason;
  ASSERT_TRUE(cuts.success) << cuts.reason;
  EXPECT_FALSE(polygons.stats.faces_with_cuts);
  EXPECT_EQ(polygons.stats.edge_points, 0u);
  EXPECT_TRUE(cuts.stats.faces_with_cuts);
  EXPECT_GT(cuts.stats.edge_points, 0u);
  EXPECT_NEAR(MeshVolume(polygons.mesh), MeshVolume(cuts.mesh), 1e-6 * MeshVolume(cuts.mesh));
  EXPECT_LT(polygons.mesh.triangles.size(), cuts.mesh.triangles.size());
  // Every vertex is a vertex of the assembly with cuts (which has the cuts besides).
  for (const Eigen::Vector3f& x : polygons.mesh.vertices) {
    float nearest = 1e9f;
    for (const Eigen::Vector3f& y : cuts.mesh.vertices)
      nearest = std::min(nearest, (x - y).norm());
    ASSERT_LT(nearest, 1e-6f);
  }
  EXPECT_EQ(CheckClosedManifold(polygons.mesh).euler_characteristic, 2);
}

// The provenance names each vertex by cone faces it lies on: three or more (two of one view and
// one of another at a viewing-edge end, three views at a triple point), each plane through its
// camera centre and its contour edge's two rays passing within 10 micrometres of the vertex
// (whose coordinates are floats).
TEST(PolyhedralHullTest, ProvenanceNamesTheFacesEachVertexLiesOn) {
  const SphereScene scene = MakeSphereScene(0.0, true);
  PolyhedralHullOptions options;
  options.keep_provenance = true;
  const PolyhedralHullResult hull = ComputePolyhedralHull(scene.cameras, scene.masks, options);
  ASSERT_TRUE(hull.success) << hull.reason;
  const HullProvenance& provenance = hull.provenance;
  ASSERT_EQ(provenance.vertex_planes.size(), hull.mesh.vertices.size());
  ASSERT_EQ(provenance.view_cameras.size(), scene.cameras.size());
  EXPECT_EQ(provenance.planes.size(), hull.stats.cone_faces);
  size_t viewing_edge_ends = 0;
  for (size_t v = 0; v < hull.mesh.vertices.size(); ++v) {
    const std::vector<int>& planes = provenance.vertex_planes[v];
    ASSERT_GE(planes.size(), 3u) << "vertex " << v;
    std::vector<int> views;
    for (const int index : planes) {
      const ConePlane& plane = provenance.planes[static_cast<size_t>(index)];
      const CameraModel& camera = scene.cameras[static_cast<size_t>(
          provenance.view_cameras[static_cast<size_t>(plane.view)])];
      const Eigen::Vector3d normal =
          (camera.R.transpose() * camera.PixelRay(plane.p).cross(camera.PixelRay(plane.q)))
              .normalized();
      const Eigen::Vector3d x = hull.mesh.vertices[v].cast<double>();
      EXPECT_LT(std::abs(normal.dot(x - camera.Center())), 1e-5) << "vertex " << v;
      views.push_back(plane.view);
    }
    std::sort(views.begin(), views.end());
    viewing_edge_ends += std::adjacent_find(views.begin(), views.end()) != views.end() ? 1 : 0;
  }
  EXPECT_GT(viewing_edge_ends, hull.mesh.vertices.size() / 2);
}

// Contours, cone planes, cone faces and the faces' polygons computed on several threads give
// exactly the mesh of one thread.
TEST(PolyhedralHullTest, ThreadsGiveTheSameMesh) {
  const SphereScene scene = MakeSphereScene(0.0, true);
  ExpectSameHullOnThreads(scene.cameras, scene.masks, 3);
}

TEST(PolyhedralHullTest, AgreesWithTheVoxelHullWithinOneVoxel) {
  for (const double voxel : {0.02, 0.01}) {
    const SphereScene scene = MakeSphereScene(0.0, true);
    const PolyhedralHullResult hull = ComputePolyhedralHull(scene.cameras, scene.masks);
    ASSERT_TRUE(hull.success) << hull.reason;
    VoxelHullOptions options;
    options.voxel_size = voxel;
    const VoxelHullResult carved = CarveVoxelHull(scene.cameras, scene.masks, options);
    ASSERT_TRUE(carved.success) << carved.reason;
    const HullDifference difference =
        CompareWithCarvedHull(hull.mesh, RasterizeMesh(hull.mesh, carved.grid), carved.grid);
    EXPECT_EQ(difference.far, 0u);
    std::printf("voxel %.0f mm: %zu of %zu voxels differ, %zu farther than a voxel\n", voxel * 1000,
                difference.differing, carved.grid.CountOccupied(), difference.far);
    EXPECT_LT(static_cast<double>(difference.differing),
              0.1 * static_cast<double>(carved.grid.CountOccupied()));
  }
}

TEST(PolyhedralHullTest, DistortedCamerasGiveTheSameSphere) {
  const SphereScene plain = MakeSphereScene(0.0, true);
  const SphereScene distorted = MakeSphereScene(-0.12, true);
  const PolyhedralHullResult a = ComputePolyhedralHull(plain.cameras, plain.masks);
  const PolyhedralHullResult b = ComputePolyhedralHull(distorted.cameras, distorted.masks);
  ASSERT_TRUE(a.success) << a.reason;
  ASSERT_TRUE(b.success) << b.reason;
  EXPECT_NEAR(MeshVolume(b.mesh) / MeshVolume(a.mesh), 1.0, 0.02);
}

TEST(PolyhedralHullTest, SymmetricRingIsClosed) {
  // The exactly symmetric ring makes four and more cone faces meet at single points, and a
  // contour vertex of one view falls on another's viewing edge: slab slivers and zero-area
  // spikes in the faces' sweeps, which the faces' polygons leave out. The assembly with the
  // sweeps' cuts cannot close this ring (callers would carve voxels). The contours are not
  // perturbed here, so the coincidences stay (SymmetricRingsOfAnyCountClose has them broken).
  const SphereScene scene = MakeSphereScene();
  PolyhedralHullOptions exact;
  exact.contour_perturbation_px = 0;
  const PolyhedralHullResult hull = ComputePolyhedralHull(scene.cameras, scene.masks, exact);
  ASSERT_TRUE(hull.success) << hull.reason;
  EXPECT_FALSE(hull.stats.faces_with_cuts);
  EXPECT_EQ(hull.stats.gaps_filled, 0u);
  const MeshCheck check = CheckClosedManifold(hull.mesh);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 2);
  // The same solid as the generic ring's within the jitter that tells them apart.
  const PolyhedralHullResult generic =
      ComputePolyhedralHull(MakeSphereScene(0.0, true).cameras, MakeSphereScene(0.0, true).masks);
  ASSERT_TRUE(generic.success) << generic.reason;
  EXPECT_NEAR(MeshVolume(hull.mesh) / MeshVolume(generic.mesh), 1.0, 0.02);
  std::printf("symmetric ring: closed, %zu triangles, %zu gaps filled (%.3g mm^2)\n",
              hull.mesh.triangles.size(), hull.stats.gaps_filled, 1e6 * hull.stats.gap_area);

  PolyhedralHullOptions with_cuts = exact;
  with_cuts.faces_as_polygons = false;
  const PolyhedralHullResult cut = ComputePolyhedralHull(scene.cameras, scene.masks, with_cuts);
  if (cut.success) {
    EXPECT_TRUE(CheckClosedManifold(cut.mesh).closed_manifold);
  } else {
    EXPECT_FALSE(cut.reason.empty());
  }
}

TEST(PolyhedralHullTest, SymmetricRingsOfAnyCountClose) {
  // Rings of 6-24 cameras evenly spaced on a circle through a sphere's centre, all aimed at
  // it, principal points at the exact image centres: every contour is the same raster circle
  // and every camera centre projects onto the middle row, so cone faces of several views meet
  // at single points, which neighbouring faces may decide differently. Where neither the
  // traced edges nor the faces close, the retry from perturbed contours (PolyhedralHullOptions)
  // breaks those coincidences: every ring closes without the cuts' assembly, those retried from
  // their traced edges without a gap to fill (25 of these 40 rings did not close without the
  // retry).
  const Eigen::Vector3d centre(0.05, -0.1, 1.0);
  constexpr double kFocalPx = 300;
  int closed_unperturbed = 0, perturbed = 0, with_gaps = 0, rings = 0;
  for (const double distance : {0.8, 1.5}) {
    for (const double radius : {0.1, 0.2}) {
      for (const int count : {6, 8, 9, 10, 11, 12, 13, 14, 16, 24}) {
        SCOPED_TRACE(testing::Message()
                     << count << " cameras at " << distance << " m, radius " << radius << " m");
        std::vector<CameraModel> cameras;
        std::vector<cv::Mat> masks;
        for (int c = 0; c < count; ++c) {
          const double angle = 2 * std::numbers::pi * c / count;
          const Eigen::Vector3d eye =
              centre + distance * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
          CameraModel camera;
          camera.id = "cam" + std::to_string(c);
          camera.width = 320;
          camera.height = 240;
          camera.K << kFocalPx, 0, 159.5, 0, kFocalPx, 119.5, 0, 0, 1;
          camera.R = LookAtRotation(eye, centre, Eigen::Vector3d::UnitZ());
          camera.t = -camera.R * eye;
          masks.push_back(SphereMask(camera, centre, radius));
          cameras.push_back(camera);
        }
        const PolyhedralHullResult hull = ComputePolyhedralHull(cameras, masks);
        ASSERT_TRUE(hull.success) << hull.reason;
        EXPECT_FALSE(hull.stats.faces_with_cuts);
        if (hull.stats.contours_perturbed) {
          EXPECT_TRUE(hull.stats.traced_edges);
          EXPECT_EQ(hull.stats.gaps_filled, 0u);
          ++perturbed;
        }
        with_gaps += hull.stats.gaps_filled > 0 ? 1 : 0;
        const MeshCheck check = CheckClosedManifold(hull.mesh);
        EXPECT_TRUE(check.closed_manifold) << check.reason;
        EXPECT_EQ(check.euler_characteristic, 2);
        // Around the sphere (up to two pixels at its far side) and inside the cones' bound.
        const double pixel = (distance + radius) / kFocalPx;
        const double bound = ConeIntersectionRadius(radius, distance, kFocalPx, count) + pixel;
        const double sphere = 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
        const double volume = MeshVolume(hull.mesh);
        EXPECT_GT(volume, sphere * std::pow(1 - 2 * pixel / radius, 3));
        EXPECT_LT(volume, sphere * std::pow(bound / radius, 3));
        for (const Eigen::Vector3f& x : hull.mesh.vertices)
          ASSERT_LE((x.cast<double>() - centre).norm(), bound);

        PolyhedralHullOptions no_retry;
        no_retry.contour_perturbation_px = 0;
        closed_unperturbed += ComputePolyhedralHull(cameras, masks, no_retry).success ? 1 : 0;
        ++rings;
      }
    }
  }
  EXPECT_GT(perturbed, 0);
  std::printf(
      "symmetric rings: %d of %d closed (%d from perturbed contours, %d with gaps filled), %d "
      "without the retry\n",
      rings, rings, perturbed, with_gaps, closed_unperturbed);
}

TEST(PolyhedralHullTest, RepeatedViewpointIntersectsItsSilhouettes) {
  // A rig that photographs from one viewpoint twice (the Middlebury temple ring's first and
  // eleventh views): the repeat's silhouette, here a smaller one, is intersected into the first
  // camera's, the same hull as that camera alone with the intersection.
  const SphereScene scene = MakeSphereScene(0.0, true);
  cv::Mat smaller;
  cv::erode(scene.masks[2], smaller, cv::Mat(), cv::Point(-1, -1), 3);
  std::vector<CameraModel> cameras = scene.cameras;
  std::vector<cv::Mat> masks = scene.masks;
  cameras.push_back(scene.cameras[2]);
  cameras.back().id = "ring2-again";
  masks.push_back(smaller);
  const PolyhedralHullResult repeated = ComputePolyhedralHull(cameras, masks);
  ASSERT_TRUE(repeated.success) << repeated.reason;
  EXPECT_EQ(repeated.stats.merged_cameras, 1u);
  std::vector<cv::Mat> expected_masks = scene.masks;
  expected_masks[2] = smaller;
  const PolyhedralHullResult expected = ComputePolyhedralHull(scene.cameras, expected_masks);
  ASSERT_TRUE(expected.success) << expected.reason;
  EXPECT_EQ(repeated.mesh.triangles.size(), expected.mesh.triangles.size());
  EXPECT_NEAR(MeshVolume(repeated.mesh), MeshVolume(expected.mesh), 1e-9);

  // From contours the repeat cannot be merged: refused, both named.
  std::vector<SilhouetteContours> contours;
  for (const cv::Mat& mask : masks)
    contours.push_back(ExtractContours(mask, ContourOptions{}));
  WorldBox bounds(Eigen::Vector3d::Constant(-2), Eigen::Vector3d::Constant(2));
  const PolyhedralHullResult from_contours = ComputePolyhedralHull(cameras, contours, bounds);
  EXPECT_FALSE(from_contours.success);
  EXPECT_NE(from_contours.reason.find("ring2-again"), std::string::npos) << from_contours.reason;

  // A camera at another's centre looking elsewhere is refused too.
  CameraModel turned = scene.cameras[2];
  const Eigen::Vector3d centre = turned.Center();
  turned.R = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix() * turned.R;
  turned.t = -turned.R * centre;
  turned.id = "ring2-turned";
  cameras.back() = turned;
  masks.back() = SphereMask(turned);
  const PolyhedralHullResult shared_centre = ComputePolyhedralHull(cameras, masks);
  EXPECT_FALSE(shared_centre.success);
  EXPECT_NE(shared_centre.reason.find("one centre"), std::string::npos) << shared_centre.reason;
}

TEST(PolyhedralHullTest, ReportsEmptyAndCutOffSilhouettes) {
  SphereScene scene = MakeSphereScene(0.0, true);
  std::vector<cv::Mat> masks = scene.masks;
  masks[3] = cv::Mat(masks[3].size(), CV_8UC1, cv::Scalar(0));  // a new image, not a write
  PolyhedralHullResult hull = ComputePolyhedralHull(scene.cameras, masks);
  EXPECT_FALSE(hull.success);
  EXPECT_NE(hull.reason.find("ring3"), std::string::npos) << hull.reason;

  masks = scene.masks;
  masks[5] = masks[5].clone();
  masks[5].colRange(0, 330).setTo(255);  // the silhouette now runs off the image
  hull = ComputePolyhedralHull(scene.cameras, masks);
  EXPECT_FALSE(hull.success);
  EXPECT_NE(hull.reason.find("border"), std::string::npos) << hull.reason;
}

// A view whose silhouette the image border cuts (the frame cropped through the sphere):
// refused by default; with the extension, a closed hull that the view bounds only inside its
// frame: between the hull of all full views and the hull without that view. A subject that
// runs far off every image (nothing bounds it there) is still refused.
TEST(PolyhedralHullTest, ExtendsSilhouettesTheImageBorderCuts) {
  const SphereScene scene = MakeSphereScene(0.0, true);
  const cv::Rect box = cv::boundingRect(scene.masks[0]);
  const int crop = box.x + box.width / 3;  // a third of the silhouette outside the frame
  std::vector<CameraModel> cameras = scene.cameras;
  std::vector<cv::Mat> masks = scene.masks;
  masks[0] = scene.masks[0].colRange(crop, scene.masks[0].cols).clone();
  cameras[0].K(0, 2) -= crop;
  cameras[0].width -= crop;
  EXPECT_FALSE(ComputePolyhedralHull(cameras, masks).success);

  PolyhedralHullOptions extend;
  extend.border_extension = 0.5;
  const PolyhedralHullResult cut = ComputePolyhedralHull(cameras, masks, extend);
  ASSERT_TRUE(cut.success) << cut.reason;
  EXPECT_TRUE(CheckClosedManifold(cut.mesh).closed_manifold);
  const PolyhedralHullResult full = ComputePolyhedralHull(scene.cameras, scene.masks);
  const PolyhedralHullResult without = ComputePolyhedralHull(
      std::vector<CameraModel>(scene.cameras.begin() + 1, scene.cameras.end()),
      std::vector<cv::Mat>(scene.masks.begin() + 1, scene.masks.end()));
  ASSERT_TRUE(full.success && without.success);
  const double volume = MeshVolume(cut.mesh);
  EXPECT_GT(volume, MeshVolume(full.mesh) * (1 + 1e-4));
  EXPECT_LT(volume, MeshVolume(without.mesh) * (1 - 1e-4));
  std::printf("border-cut view: volume %.5f m^3 between %.5f (all views) and %.5f (without it)\n",
              volume, MeshVolume(full.mesh), MeshVolume(without.mesh));

  // A pole through every frame, top to bottom: no view bounds it above or below.
  masks = scene.masks;
  for (size_t v = 0; v < masks.size(); ++v) {
    const cv::Rect sphere = cv::boundingRect(scene.masks[v]);
    masks[v] = cv::Mat::zeros(scene.masks[v].size(), CV_8UC1);
    masks[v].colRange(sphere.x, sphere.x + sphere.width).setTo(255);
  }
  const PolyhedralHullResult pole = ComputePolyhedralHull(scene.cameras, masks, extend);
  EXPECT_FALSE(pole.success);
  EXPECT_NE(pole.reason.find("beyond the image border"), std::string::npos) << pole.reason;
}

}  // namespace
}  // namespace silnet::aggregator

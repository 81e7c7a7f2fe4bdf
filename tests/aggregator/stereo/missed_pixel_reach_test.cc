// The last silhouette step of the stereo surface (aggregator/stereo/missed_pixel_reach.h): a
// sphere model slightly too small for its exact views is moved out to cover the inner
// silhouette pixels it missed, without covering an outer pixel or missing one it covered;
// pixels no consistent model covers are left as they are.

#include "aggregator/stereo/missed_pixel_reach.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/mesh_check.h"
#include "aggregator/stereo/model_evaluation.h"
#include "test_spheres.h"

namespace silnet::aggregator {
namespace {

const Eigen::Vector3d kCentre(0.0, 0.0, 1.0);
constexpr double kRadius = 0.1;
constexpr double kDistance = 0.8;
constexpr double kFocal = 300;
constexpr double kFootprint = kDistance / kFocal;  // metres per pixel at the sphere's centre

std::vector<StereoView> SphereViews() {
  return testing::TexturedSphereViews(kCentre, kRadius, 6, kDistance, 320, 240, kFocal);
}

// The sphere `footprints` pixel footprints smaller than the views' one.
TriangleMesh SmallerSphere(double footprints) {
  return testing::Icosphere(kCentre, kRadius - footprints * kFootprint, 5);
}

size_t Sum(const std::vector<SilhouetteConsistency>& views, size_t SilhouetteConsistency::*field) {
  size_t sum = 0;
  for (const SilhouetteConsistency& v : views)
    sum += v.*field;
  return sum;
}

// Checks what the step promises against the views as they were before it: no outer pixel
// covered, no inner pixel covered before and missed after (pixels `margin_px` inside or
// outside the outline), only vertices moved (each at most `max_move` metres), the mesh still
// closed.
void ExpectConsistentStep(const std::vector<StereoView>& views, const TriangleMesh& before,
                          const TriangleMesh& after, double max_move,
                          double margin_px = kSilhouetteMarginPx) {
  ASSERT_EQ(before.vertices.size(), after.vertices.size());
  EXPECT_EQ(before.triangles, after.triangles);
  EXPECT_TRUE(CheckClosedManifold(after).closed_manifold);
  for (size_t i = 0; i < before.vertices.size(); ++i)
    EXPECT_LE((after.vertices[i] - before.vertices[i]).norm(), max_move) << "vertex " << i;
  for (size_t v = 0; v < views.size(); ++v) {
    const cv::Mat inner = InnerSilhouettePixels(views[v].mask, margin_px);
    const cv::Mat was = RenderMeshSilhouette(before, views[v].camera);
    const cv::Mat now = RenderMeshSilhouette(after, views[v].camera);
    EXPECT_EQ(cv::countNonZero(inner & was & ~now), 0) << "view " << v;
    const SilhouetteConsistency c = CompareSilhouetteConsistency(now, views[v].mask, margin_px);
    EXPECT_EQ(c.covered_outer, 0u) << "view " << v;
  }
}

TEST(MissedPixelReachTest, ASphereTooSmallIsMovedOutToItsSilhouettes) {
  const std::vector<StereoView> views = SphereViews();
  const TriangleMesh before = SmallerSphere(1.6);
  const std::vector<SilhouetteConsistency> was = MeasureSilhouetteConsistency(before, views);
  for (const SilhouetteConsistency& c : was) {
    ASSERT_GT(c.missed_inner, 50u);  // a ring round the rim
    ASSERT_EQ(c.missed_uncoverable, 0u);
  }
  TriangleMesh mesh = before;
  const PixelReachOptions options;
  const PixelReachStats stats = ReachMissedPixels(views, kFootprint, options, &mesh);
  const std::vector<SilhouetteConsistency> now = MeasureSilhouetteConsistency(mesh, views);
  const size_t missed_before = Sum(was, &SilhouetteConsistency::missed_inner);
  const size_t missed_after = Sum(now, &SilhouetteConsistency::missed_inner);
  EXPECT_EQ(stats.missed_before, missed_before);
  EXPECT_EQ(stats.coverable_before, missed_before);
  EXPECT_EQ(stats.missed_after, missed_after);
  EXPECT_GT(stats.moved, 0u);
  EXPECT_LE(missed_after, missed_before / 20) << missed_before << " -> " << missed_after;
  ExpectConsistentStep(views, before, mesh, options.max_move_footprints * kFootprint * 1.0001);
}

TEST(MissedPixelReachTest, PixelsNoConsistentModelCoversAreLeftMissed) {
  std::vector<StereoView> views = SphereViews();
  // A blob beside the sphere in view 0 only: its pixels' rays leave the other silhouettes.
  const cv::Rect box = cv::boundingRect(views[0].mask);
  const cv::Rect patch(box.br().x + box.width / 6, box.y + box.height / 2 - 5, 10, 10);
  views[0].mask(patch).setTo(255);
  const TriangleMesh before = testing::Icosphere(kCentre, kRadius, 5);
  const std::vector<SilhouetteConsistency> was = MeasureSilhouetteConsistency(before, views);
  ASSERT_GT(was[0].missed_uncoverable, 30u);
  TriangleMesh mesh = before;
  const PixelReachStats stats = ReachMissedPixels(views, kFootprint, {}, &mesh);
  const std::vector<SilhouetteConsistency> now = MeasureSilhouetteConsistency(mesh, views);
  EXPECT_EQ(now[0].missed_uncoverable, was[0].missed_uncoverable);
  EXPECT_EQ(stats.coverable_before, Sum(was, &SilhouetteConsistency::missed_inner) -
                                        Sum(was, &SilhouetteConsistency::missed_uncoverable));
  ExpectConsistentStep(views, before, mesh,
                       PixelReachOptions{}.max_move_footprints * kFootprint * 1.0001);
}

TEST(MissedPixelReachTest, ARoughSurfaceKeepsEveryPixelItCoveredAndCoversNoOuterOne) {
  const std::vector<StereoView> views = SphereViews();
  // Vertices moved in and out along the radius by up to 1.5 footprints: the moves crowd and
  // fold the surface, and moves that would uncover a pixel are undone.
  TriangleMesh before = SmallerSphere(1.0);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> offset(-1.5 * kFootprint, 0.5 * kFootprint);
  for (Eigen::Vector3f& x : before.vertices) {
    const Eigen::Vector3d radial = (x.cast<double>() - kCentre).normalized();
    x += (offset(random) * radial).cast<float>();
  }
  const std::vector<SilhouetteConsistency> was = MeasureSilhouetteConsistency(before, views);
  ASSERT_EQ(Sum(was, &SilhouetteConsistency::covered_outer), 0u);
  TriangleMesh mesh = before;
  const PixelReachStats stats = ReachMissedPixels(views, kFootprint, {}, &mesh);
  const size_t missed_before = Sum(was, &SilhouetteConsistency::missed_inner);
  const size_t missed_after =
      Sum(MeasureSilhouetteConsistency(mesh, views), &SilhouetteConsistency::missed_inner);
  EXPECT_EQ(stats.missed_before, missed_before);
  EXPECT_EQ(stats.missed_after, missed_after);
  EXPECT_LE(missed_after, missed_before / 4) << missed_before << " -> " << missed_after;
  ExpectConsistentStep(views, before, mesh,
                       PixelReachOptions{}.max_move_footprints * kFootprint * 1.0001);
}

TEST(MissedPixelReachTest, MovesThatCoverAnOuterPixelAreUndone) {
  // With no margin every background pixel is outer, and moves pushed almost a pixel past
  // their pixel centres cover some: those moves are undone.
  const std::vector<StereoView> views = SphereViews();
  const TriangleMesh before = SmallerSphere(1.6);
  TriangleMesh mesh = before;
  PixelReachOptions options;
  options.margin_px = 0;
  options.beyond_px = 0.95;
  const PixelReachStats stats = ReachMissedPixels(views, kFootprint, options, &mesh);
  EXPECT_GT(stats.undone, 0u);
  EXPECT_GT(stats.moved, 0u);
  EXPECT_LT(stats.missed_after, stats.missed_before);
  ExpectConsistentStep(views, before, mesh, options.max_move_footprints * kFootprint * 1.0001, 0);
}

TEST(MissedPixelReachTest, InvalidOptionsAreRefused) {
  std::string reason;
  PixelReachOptions options;
  EXPECT_TRUE(options.IsValid(&reason));
  options.beyond_px = 1.5;
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("beyond"), std::string::npos) << reason;
  options = {};
  options.search_px = 0;
  EXPECT_FALSE(options.IsValid(&reason));
  options = {};
  options.rounds = -1;
  EXPECT_FALSE(options.IsValid(&reason));
}

}  // namespace
}  // namespace silnet::aggregator

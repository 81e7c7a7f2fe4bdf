// The Middlebury dino and temple sparse rings (shared data folder): 16 calibrated views each,
// silhouettes by threshold that agree with the given cameras (checked by reprojecting the
// exact polyhedral hull built from them), and their export as stills folders.

#include "aggregator/stereo/middlebury_dataset.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/imgproc.hpp>

#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/stereo_hull.h"
#include "aggregator/stereo/stills_folder.h"
#include "tests/support/real_data.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

const std::filesystem::path kData = SILNET_SHARED_DATA_DIR;

// How far the hull of a ring's silhouettes may disagree with them, per view (fractions of
// the silhouette's pixels).
struct Limits {
  double missed_far = 0;    // missed farther than 2 px from the outline
  double extra = 0;         // hull pixels outside the silhouette, views that built the hull
  double extra_unused = 0;  // the same, views left out of the hull (their part leaves the frame)
};

// Builds the polyhedral hull from the silhouettes that stay off the image border (the hull
// code refuses the others: the object may continue outside the frame), reprojects it into
// every view, prints the figures and checks them against `limits`.
void ExpectHullAgreesWithSilhouettes(const StereoViews& views, const std::string& name,
                                     const Limits& limits) {
  std::vector<CameraModel> cameras;
  std::vector<cv::Mat> masks;
  std::vector<bool> used;
  for (const StereoView& view : views.views) {
    used.push_back(!TouchesBorder(view.mask));
    if (!used.back()) continue;
    cameras.push_back(view.camera);
    masks.push_back(view.mask);
  }
  const PolyhedralHullResult hull = ComputePolyhedralHull(cameras, masks);
  std::printf("%s: polyhedral hull of %zu views: %s, %zu triangles\n", name.c_str(), cameras.size(),
              hull.success ? "closed" : hull.reason.c_str(), hull.mesh.triangles.size());
  ASSERT_TRUE(hull.success) << hull.reason;
  const std::vector<ViewReprojection> reprojection =
      MeasureHullReprojection(hull.mesh, views.Cameras(), views.Masks());
  for (size_t c = 0; c < reprojection.size(); ++c) {
    const ViewReprojection& v = reprojection[c];
    const std::string& id = views.views[c].camera.id;
    std::printf(
        "  %-12s %6zu px  missed %.3f %% (> 2 px from the outline %.3f %%)  extra %.3f %%%s\n",
        id.c_str(), v.silhouette_pixels, 100 * v.missed_fraction, 100 * v.missed_far_fraction,
        100 * v.spurious_fraction, used[c] ? "" : "  (touches the border, not in the hull)");
    EXPECT_LE(v.missed_far_fraction, limits.missed_far) << id;
    EXPECT_LE(v.spurious_fraction, used[c] ? limits.extra : limits.extra_unused) << id;
  }
}

TEST(MiddleburyDatasetTest, DinoLoadsSixteenViews) {
  const std::filesystem::path folder = kData / "middlebury-dinoSparseRing";
  SILNET_REQUIRE_REAL_DATA(folder);
  const StereoViews views = LoadMiddlebury(folder);
  ASSERT_EQ(views.views.size(), 16u);
  EXPECT_EQ(views.views[0].camera.id, "dinoSR0001");
  EXPECT_DOUBLE_EQ(views.views[0].camera.K(0, 0), 3310.4);
  EXPECT_DOUBLE_EQ(views.views[0].camera.K(1, 2), 200.55);
  EXPECT_NEAR(views.views[0].camera.t.z(), 0.673097816109, 1e-12);
  for (const StereoView& view : views.views) {
    EXPECT_EQ(view.image.size(), cv::Size(640, 480));
    EXPECT_EQ(view.silhouette_source, MaskOrigin::kThreshold);
    EXPECT_TRUE((view.camera.R * view.camera.R.transpose()).isIdentity(1e-12));
    EXPECT_FALSE(view.camera.HasDistortion());
  }
  // The authors could not get a good silhouette of view 6 (dinoSR_good_silhouette_images.txt).
  ASSERT_EQ(views.warnings.size(), 1u);
  EXPECT_NE(views.warnings[0].find("dinoSR0006"), std::string::npos) << views.warnings[0];
}

TEST(MiddleburyDatasetTest, TempleLoadsSixteenViews) {
  const std::filesystem::path folder = kData / "middlebury-templeSparseRing";
  SILNET_REQUIRE_REAL_DATA(folder);
  const StereoViews views = LoadMiddlebury(folder);
  ASSERT_EQ(views.views.size(), 16u);
  EXPECT_TRUE(views.warnings.empty());
  EXPECT_EQ(views.views[15].camera.id, "templeSR0016");
  EXPECT_DOUBLE_EQ(views.views[15].camera.K(0, 0), 1520.4);
  for (const StereoView& view : views.views)
    EXPECT_EQ(view.mask.size(), cv::Size(640, 480));
}

// Measured (docs/PERFORMANCE.md): dino views 1-3 leave the frame, so the hull is built from
// the other 13 (closed). Missed beyond 2 px: worst 1.29 % (dinoSR0012; its neighbours 11 and
// 9 0.80 % and 0.26 %, where dark shadow slivers at the outline stay below the threshold in
// one view but not in another), the rest <= 0.29 %. Extra: <= 0.11 % in the 13 views, 1.4 to
// 3.6 % in views 1-3, which did not carve the hull.
TEST(MiddleburyDatasetTest, DinoSilhouettesAgreeWithTheCameras) {
  const std::filesystem::path folder = kData / "middlebury-dinoSparseRing";
  SILNET_REQUIRE_REAL_DATA(folder);
  Limits limits;
  limits.missed_far = 0.016;
  limits.extra = 0.004;
  limits.extra_unused = 0.09;
  ExpectHullAgreesWithSilhouettes(LoadMiddlebury(folder), "dino", limits);
}

// Measured (docs/PERFORMANCE.md): all 16 temple views stay off the border. Photographs 1 and
// 11 were taken by one camera (the ring repeats its first view): the hull intersects their
// silhouettes into one cone, and closes (it did not while their coincident cones made every
// face of one meet the other's). Missed beyond 2 px: worst 0.55 % (templeSR0006); extra: worst
// 0.27 %.
TEST(MiddleburyDatasetTest, TempleSilhouettesAgreeWithTheCameras) {
  const std::filesystem::path folder = kData / "middlebury-templeSparseRing";
  SILNET_REQUIRE_REAL_DATA(folder);
  Limits limits;
  limits.missed_far = 0.008;
  limits.extra = 0.005;
  limits.extra_unused = 0.005;
  const StereoViews views = LoadMiddlebury(folder);
  ExpectHullAgreesWithSilhouettes(views, "temple", limits);
  // The stereo job's hull names the repeated viewpoint and, as the exact hull misses 0.63 % of
  // the pixels >= 1 px inside the silhouettes (the given cameras are a pixel off), is built
  // again from covering contours reaching 1.3 px beyond the pixel centres: 0.38 % missed, no
  // pixel >= 1 px outside covered.
  CutSilhouettes silhouettes;
  silhouettes.cameras = views.Cameras();
  silhouettes.masks = views.Masks();
  std::vector<std::string> warnings;
  const PolyhedralHullResult hull = ComputeStereoHull(silhouettes, 0, &warnings);
  ASSERT_TRUE(hull.success) << hull.reason;
  EXPECT_EQ(hull.stats.merged_cameras, 1u);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("templeSR0011 was taken from the viewpoint of templeSR0001"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("built again from covering contours"), std::string::npos)
      << warnings[1];
  EXPECT_LT(MissedInnerShare(hull.mesh, silhouettes.cameras, silhouettes.masks), 0.005);
  for (const SilhouetteConsistency& view : MeasureSilhouetteConsistency(hull.mesh, views.views))
    EXPECT_EQ(view.covered_outer, 0u) << view.camera_id;
}

// A hole in the silhouette brighter than the backdrop around the subject is a shadow pocket
// and filled whatever its size; one as dark as the backdrop is a gap and stays.
TEST(MiddleburyDatasetTest, FillsShadowPocketsAndKeepsGapsThatShowTheBackdrop) {
  cv::Mat image(240, 320, CV_8UC3);
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(16));  // black backdrop with noise
  cv::circle(image, {160, 120}, 100, cv::Scalar::all(200), cv::FILLED);
  image(cv::Rect(100, 60, 30, 30)).setTo(cv::Scalar::all(30));  // shadowed pocket, 900 px
  cv::Mat gap = image(cv::Rect(190, 140, 30, 30));
  cv::randu(gap, cv::Scalar::all(0), cv::Scalar::all(16));  // backdrop seen through a gap
  DarkBackgroundOptions options = MiddleburyPreset("dinoSR");
  ASSERT_LT(options.max_hole_area, 900);
  const cv::Mat mask = ThresholdDarkBackground(image, options);
  EXPECT_EQ(cv::countNonZero(mask(cv::Rect(100, 60, 30, 30))), 900);
  EXPECT_EQ(cv::countNonZero(mask(cv::Rect(192, 142, 26, 26))), 0);

  options.shadow_pocket_percentile = 2;  // off: both holes stay
  const cv::Mat unfilled = ThresholdDarkBackground(image, options);
  EXPECT_EQ(cv::countNonZero(unfilled(cv::Rect(102, 62, 26, 26))), 0);
}

// The presets are what makes the silhouettes agree: the authors' generic 0.19 (48) lets the
// temple's lit backdrop cloth into views 1, 10, 11 and 14, where it reaches the image border.
TEST(MiddleburyDatasetTest, TheGenericThresholdTakesTheTemplesBackdrop) {
  const std::filesystem::path folder = kData / "middlebury-templeSparseRing";
  SILNET_REQUIRE_REAL_DATA(folder);
  const StereoViews generic = LoadMiddlebury(folder, DarkBackgroundOptions{});
  const StereoViews preset = LoadMiddlebury(folder);
  int generic_touching = 0, preset_touching = 0;
  for (size_t v = 0; v < generic.views.size(); ++v) {
    generic_touching += TouchesBorder(generic.views[v].mask) ? 1 : 0;
    preset_touching += TouchesBorder(preset.views[v].mask) ? 1 : 0;
  }
  std::printf("temple views touching the border: generic %d, preset %d\n", generic_touching,
              preset_touching);
  EXPECT_EQ(generic_touching, 4);
  EXPECT_EQ(preset_touching, 0);
}

TEST(MiddleburyDatasetTest, ExportsAStillsFolderThatLoadsBack) {
  const std::filesystem::path folder = kData / "middlebury-dinoSparseRing";
  SILNET_REQUIRE_REAL_DATA(folder);
  const silnet::testing::TempDir dir;
  const StereoViews original = LoadMiddlebury(folder);
  const std::filesystem::path calibration = WriteMiddleburyAsStillsFolder(folder, dir / "dino");
  EXPECT_TRUE(std::filesystem::exists(dir / "dino" / "dinoSR0007" / "stills" / "000000.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "dino" / "dinoSR0007" / "masks" / "000000.png"));
  const StereoViews loaded = LoadStillsFolder(dir / "dino", calibration);
  EXPECT_TRUE(loaded.warnings.empty());
  ASSERT_EQ(loaded.views.size(), 16u);
  for (size_t v = 0; v < 16; ++v) {
    const StereoView& a = original.views[v];
    const StereoView& b = loaded.views[v];
    EXPECT_EQ(a.camera.id, b.camera.id);
    EXPECT_EQ(b.silhouette_source, MaskOrigin::kMaskFile);
    EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0) << a.camera.id;
    EXPECT_EQ(cv::norm(a.mask, b.mask, cv::NORM_INF), 0) << a.camera.id;
    EXPECT_TRUE(a.camera.K.isApprox(b.camera.K, 1e-12));
    EXPECT_TRUE(a.camera.R.isApprox(b.camera.R, 1e-12));
    EXPECT_TRUE(a.camera.t.isApprox(b.camera.t, 1e-12));
  }
}

}  // namespace
}  // namespace silnet::aggregator

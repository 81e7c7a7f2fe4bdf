// Silhouette pixels no consistent model can cover (aggregator/stereo/uncoverable_pixels.h):
// none on exact views of a sphere, every one of a blob that only one view sees, and the model
// figures tell a model's own misses from those; and the outer pixels a model covers in trade
// for such pixels (traded_outer_pixels.h) told apart from the ones it covers for nothing.

#include "aggregator/stereo/uncoverable_pixels.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "aggregator/stereo/model_evaluation.h"
#include "shared/util/check.h"
#include "test_spheres.h"

namespace silnet::aggregator {
namespace {

const Eigen::Vector3d kCentre(0.0, 0.0, 1.0);
constexpr double kRadius = 0.1;

std::vector<StereoView> SphereViews() {
  return testing::TexturedSphereViews(kCentre, kRadius, 6, 0.8, 320, 240, 300);
}

TEST(UncoverablePixelsTest, ExactViewsOfASphereAreCoverableEverywhere) {
  const std::vector<StereoView> views = SphereViews();
  const GrownSilhouettes grown = GrowSilhouettes(views, kSilhouetteMarginPx);
  for (size_t v = 0; v < views.size(); ++v) {
    ASSERT_GT(cv::countNonZero(views[v].mask), 3000);
    EXPECT_FALSE(grown.border_cut[v]);
    EXPECT_EQ(CountUncoverable(views, grown, v, views[v].mask), 0u) << "view " << v;
  }
}

// A square blob of `side` pixels added to view 0's silhouette beside the sphere, a sixth of
// its width away; returns the blob's pixels (CV_8UC1, 255).
cv::Mat AddBlobBesideTheSphere(std::vector<StereoView>& views, int side) {
  cv::Mat blob = cv::Mat::zeros(views[0].mask.size(), CV_8UC1);
  const cv::Rect box = cv::boundingRect(views[0].mask);
  const cv::Rect patch(box.br().x + box.width / 6, box.y + box.height / 2 - side / 2, side, side);
  SILNET_CHECK((patch & cv::Rect(0, 0, blob.cols, blob.rows)) == patch);
  blob(patch).setTo(255);
  views[0].mask |= blob;
  return blob;
}

TEST(UncoverablePixelsTest, ABlobOnlyOneViewSeesIsUncoverable) {
  std::vector<StereoView> views = SphereViews();
  const cv::Mat blob = AddBlobBesideTheSphere(views, 10);
  const GrownSilhouettes grown = GrowSilhouettes(views, kSilhouetteMarginPx);
  EXPECT_EQ(CountUncoverable(views, grown, 0, blob), 100u);
  EXPECT_EQ(CountUncoverable(views, grown, 0, views[0].mask), 100u);
  // The other views' pixels stay coverable: view 0's blob only widens its cone.
  for (size_t v = 1; v < views.size(); ++v)
    EXPECT_EQ(CountUncoverable(views, grown, v, views[v].mask), 0u) << "view " << v;

  // Without the blob in the silhouette check, a sphere model misses exactly the blob's inner
  // pixels, all uncoverable; a smaller sphere also misses coverable ones.
  const std::vector<SilhouetteConsistency> exact =
      MeasureSilhouetteConsistency(testing::Icosphere(kCentre, kRadius, 5), views);
  EXPECT_EQ(exact[0].missed_inner, exact[0].missed_uncoverable);
  EXPECT_GT(exact[0].missed_uncoverable, 30u);  // the blob's pixels >= 1 px inside its outline
  const std::vector<SilhouetteConsistency> smaller =
      MeasureSilhouetteConsistency(testing::Icosphere(kCentre, 0.9 * kRadius, 5), views);
  EXPECT_EQ(smaller[0].missed_uncoverable, exact[0].missed_uncoverable);
  EXPECT_GT(smaller[0].missed_inner, exact[0].missed_inner + 500);
  for (size_t v = 1; v < views.size(); ++v) {
    EXPECT_EQ(exact[v].missed_uncoverable, 0u) << "view " << v;
    EXPECT_GT(smaller[v].missed_inner, 500u) << "view " << v;
    EXPECT_EQ(smaller[v].missed_uncoverable, 0u) << "view " << v;
  }
}

// The point at `depth` metres in front of view `v`'s camera on the ray of `pixel`.
Eigen::Vector3d PointOnRay(const StereoView& view, const Eigen::Vector2d& pixel, double depth) {
  const CameraModel& camera = view.camera;
  return camera.R.transpose() * (depth * camera.PixelRay(pixel)) + camera.Center();
}

TEST(UncoverablePixelsTest, OuterPixelsCoveredForAnotherViewsUncoverablePixelsAreTraded) {
  std::vector<StereoView> views = SphereViews();
  const cv::Mat blob = AddBlobBesideTheSphere(views, 20);
  const cv::Rect patch = cv::boundingRect(blob);
  const Eigen::Vector2d blob_centre(patch.x + (patch.width - 1) / 2.0,
                                    patch.y + (patch.height - 1) / 2.0);
  const double sphere_depth = (kCentre - views[0].camera.Center()).norm();
  const TriangleMesh sphere = testing::Icosphere(kCentre, kRadius, 4);
  const auto sum = [](const std::vector<SilhouetteConsistency>& c,
                      size_t SilhouetteConsistency::*field) {
    size_t total = 0;
    for (size_t v = 1; v < c.size(); ++v)
      total += c[v].*field;
    return total;
  };

  // A ball on the blob's rays, nearer view 0 than the sphere: view 0 sees it within the
  // blob's inner pixels (6 px of the blob's 9 across), the other views mostly outside the
  // sphere. Every outer pixel it covers there is the price of covering the blob.
  const double depth = 0.6 * sphere_depth;
  const double radius = 6.0 / 300.0 * depth;
  TriangleMesh traded = sphere;
  testing::AppendPiece(testing::Icosphere(PointOnRay(views[0], blob_centre, depth), radius, 3),
                       &traded);
  const std::vector<SilhouetteConsistency> with_ball = MeasureSilhouetteConsistency(traded, views);
  EXPECT_EQ(with_ball[0].covered_outer, 0u);
  EXPECT_EQ(with_ball[0].missed_inner, with_ball[0].missed_uncoverable);
  EXPECT_LT(with_ball[0].missed_uncoverable, 300u);  // the blob's ring the ball leaves
  EXPECT_GT(sum(with_ball, &SilhouetteConsistency::covered_outer), 100u);
  for (size_t v = 1; v < views.size(); ++v)
    EXPECT_EQ(with_ball[v].covered_outer_traded, with_ball[v].covered_outer) << "view " << v;
  // Measured on one thread: the same figures.
  const std::vector<SilhouetteConsistency> one_thread =
      MeasureSilhouetteConsistency(traded, views, kSilhouetteMarginPx, 1);
  ASSERT_EQ(one_thread.size(), with_ball.size());
  for (size_t v = 0; v < views.size(); ++v) {
    const SilhouetteConsistency &a = one_thread[v], &b = with_ball[v];
    EXPECT_EQ(a.camera_id, b.camera_id);
    EXPECT_EQ(std::tie(a.silhouette_pixels, a.inner_pixels, a.missed_inner, a.missed_uncoverable,
                       a.outer_pixels, a.covered_outer, a.covered_outer_traded, a.missed_pixels,
                       a.covered_background),
              std::tie(b.silhouette_pixels, b.inner_pixels, b.missed_inner, b.missed_uncoverable,
                       b.outer_pixels, b.covered_outer, b.covered_outer_traded, b.missed_pixels,
                       b.covered_background))
        << "view " << v;
  }

  // The same ball on the axis between view 0 and the sphere: view 0 sees it inside the
  // sphere's silhouette, where every pixel is coverable, so its outer pixels elsewhere are
  // the model's own error. So are those of a ball above the sphere that no view asks for.
  TriangleMesh in_front = sphere;
  testing::AppendPiece(testing::Icosphere(PointOnRay(views[0], {159.5, 119.5}, depth), radius, 3),
                       &in_front);
  TriangleMesh dust = sphere;
  testing::AppendPiece(testing::Icosphere(kCentre + Eigen::Vector3d(0, 0, 0.2), radius, 3), &dust);
  for (const TriangleMesh* model : {&in_front, &dust}) {
    const std::vector<SilhouetteConsistency> c = MeasureSilhouetteConsistency(*model, views);
    EXPECT_GT(sum(c, &SilhouetteConsistency::covered_outer), 100u);
    for (size_t v = 0; v < views.size(); ++v)
      EXPECT_EQ(c[v].covered_outer_traded, 0u) << "view " << v;
  }
}

TEST(UncoverablePixelsTest, BeyondTheImageOfABorderCutViewNothingIsKnown) {
  std::vector<StereoView> views = SphereViews();
  // View 1 loses the right half of its image: its silhouette now touches the border. Rays of
  // the other views that leave its image there are not decided by it.
  StereoView& cut = views[1];
  const cv::Rect box = cv::boundingRect(cut.mask);
  const int keep = box.x + box.width / 2;
  StereoView narrow = cut;
  narrow.mask = cut.mask(cv::Rect(0, 0, keep, cut.mask.rows)).clone();
  narrow.image = cut.image(cv::Rect(0, 0, keep, cut.image.rows)).clone();
  narrow.camera.width = keep;
  views[1] = narrow;
  const GrownSilhouettes grown = GrowSilhouettes(views, kSilhouetteMarginPx);
  EXPECT_TRUE(grown.border_cut[1]);
  for (size_t v = 0; v < views.size(); ++v)
    EXPECT_EQ(CountUncoverable(views, grown, v, views[v].mask), 0u) << "view " << v;
}

}  // namespace
}  // namespace silnet::aggregator

// Silhouette pixels no consistent model can cover (aggregator/stereo/uncoverable_pixels.h):
// none on exact views of a sphere, every one of a blob that only one view sees, and the model
// figures tell a model's own misses from those.

#include "aggregator/stereo/uncoverable_pixels.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "aggregator/stereo/model_evaluation.h"
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

TEST(UncoverablePixelsTest, ABlobOnlyOneViewSeesIsUncoverable) {
  std::vector<StereoView> views = SphereViews();
  cv::Mat blob = cv::Mat::zeros(views[0].mask.size(), CV_8UC1);
  const cv::Rect box = cv::boundingRect(views[0].mask);
  // Beside the sphere, a sixth of its width away.
  const cv::Rect patch(box.br().x + box.width / 6, box.y + box.height / 2 - 5, 10, 10);
  ASSERT_TRUE((patch & cv::Rect(0, 0, blob.cols, blob.rows)) == patch);
  blob(patch).setTo(255);
  views[0].mask |= blob;
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

// The stereo job's hull where the cameras and the silhouettes disagree by about a pixel
// (aggregator/stereo/stereo_hull.h): built again from contours reaching beyond the pixel
// centres, so it misses fewer silhouette pixels and still covers none beyond the margin;
// consistent silhouettes keep the exact hull.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/stereo/model_evaluation.h"
#include "aggregator/stereo/stereo_hull.h"
#include "simulated_stills.h"

namespace silnet::aggregator {
namespace {

// The statue's stills (8 ring views at 480x360), rendered once.
const std::vector<StereoView>& Stills() {
  static const testing::SimulatedStills stills = testing::MakeSimulatedStills(8, 480, 360, 1);
  return stills.views.views;
}

CutSilhouettes AsCutSilhouettes(const std::vector<StereoView>& views) {
  CutSilhouettes out;
  for (const StereoView& view : views) {
    out.cameras.push_back(view.camera);
    out.masks.push_back(view.mask);
  }
  return out;
}

bool Widened(const std::vector<std::string>& warnings) {
  for (const std::string& warning : warnings)
    if (warning.find("built again") != std::string::npos) return true;
  return false;
}

TEST(StereoHullTest, ConsistentSilhouettesKeepTheExactHull) {
  const CutSilhouettes cut = AsCutSilhouettes(Stills());
  std::vector<std::string> warnings;
  const PolyhedralHullResult hull = ComputeStereoHull(cut, 1, &warnings);
  ASSERT_TRUE(hull.success) << hull.reason;
  EXPECT_TRUE(warnings.empty());
  EXPECT_LE(MissedInnerShare(hull.mesh, cut.cameras, cut.masks), kWidenedHullMissedShare);
}

TEST(StereoHullTest, SilhouettesAPixelOrTwoOffGetAWidenedHullThatStaysInsideTheMargin) {
  for (const auto& [dx, dy] : {std::pair{2, 0}, std::pair{0, 2}, std::pair{2, 3}}) {
    SCOPED_TRACE("view 2 shifted by " + std::to_string(dx) + ", " + std::to_string(dy) + " px");
    std::vector<StereoView> views = Stills();
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
    cv::Mat shifted;
    cv::warpAffine(views[2].mask, shifted, shift, views[2].mask.size(), cv::INTER_NEAREST);
    views[2].mask = shifted;
    const CutSilhouettes cut = AsCutSilhouettes(views);
    const PolyhedralHullResult exact = ComputePolyhedralHull(cut.cameras, cut.masks);
    ASSERT_TRUE(exact.success) << exact.reason;
    std::vector<std::string> warnings;
    const PolyhedralHullResult widened = ComputeStereoHull(cut, 1, &warnings);
    ASSERT_TRUE(widened.success) << widened.reason;
    EXPECT_TRUE(Widened(warnings));
    const double exact_missed = MissedInnerShare(exact.mesh, cut.cameras, cut.masks);
    const double widened_missed = MissedInnerShare(widened.mesh, cut.cameras, cut.masks);
    std::printf("[ stereo hull ] view 2 off by (%d, %d) px: missed %.3f %% -> %.3f %%\n", dx, dy,
                100 * exact_missed, 100 * widened_missed);
    EXPECT_GT(exact_missed, kWidenedHullMissedShare);
    EXPECT_LT(widened_missed, 0.7 * exact_missed);
    for (const SilhouetteConsistency& view : MeasureSilhouetteConsistency(widened.mesh, views))
      EXPECT_EQ(view.covered_outer, 0u) << view.camera_id;
  }
}

}  // namespace
}  // namespace silnet::aggregator

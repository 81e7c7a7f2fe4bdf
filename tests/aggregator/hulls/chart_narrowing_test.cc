#include "aggregator/hulls/chart_narrowing.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace silnet::aggregator {
namespace {

// The chart line through (lambda0, w0) and (lambda1, w1), spanning between them.
ChartLine Line(double lambda0, double w0, double lambda1, double w1) {
  ChartLine line;
  line.slope = (w1 - w0) / (lambda1 - lambda0);
  line.intercept = w0 - line.slope * lambda0;
  line.coefficients = Eigen::Vector3d(line.slope, -1, line.intercept);
  line.lambda_lo = std::min(lambda0, lambda1);
  line.lambda_hi = std::max(lambda0, lambda1);
  line.w_lo = std::min(w0, w1);
  line.w_hi = std::max(w0, w1);
  return line;
}

// The sweep's view of the silhouette at (lambda, w).
bool Inside(const ViewBuild& build, double lambda, double w) {
  bool inside = build.corner_inside;
  for (const ChartLine& line : build.lines) {
    inside ^= line.bottom_crossing >= 0 && line.bottom_crossing < lambda;
    inside ^= line.lambda_lo < lambda && lambda < line.lambda_hi && line.WAt(lambda) < w;
  }
  return inside;
}

ViewBuild Box(double w_min, double w_max, bool corner_inside) {
  ViewBuild build;
  build.w_min = w_min;
  build.w_max = w_max;
  build.corner_inside = corner_inside;
  return build;
}

TEST(ChartNarrowingTest, BandBetweenTwoLinesSpansTheirExtent) {
  ViewBuild band = Box(0, 10, false);
  band.lines = {Line(0, 2, 1, 3), Line(0, 6, 1, 5)};
  std::vector<double> scratch;
  EXPECT_FALSE(ReachesTop(band, scratch));
  const auto [low, high] = SilhouetteWRange(band, scratch);
  EXPECT_DOUBLE_EQ(low, 2);
  EXPECT_DOUBLE_EQ(high, 6);
}

TEST(ChartNarrowingTest, SidesTheSilhouetteReaches) {
  std::vector<double> scratch;
  // Inside everywhere: the whole box.
  const ViewBuild all = Box(1, 9, true);
  EXPECT_EQ(SilhouetteWRange(all, scratch), std::make_pair(1.0, 9.0));
  // Inside right of a line entering through the bottom at lambda 0.5 and leaving through the
  // top at 0.9: it reaches the top on (0.9, 1).
  ViewBuild right = Box(1, 9, false);
  right.lines = {Line(0.5, 1, 0.9, 9)};
  right.lines[0].bottom_crossing = 0.5;
  EXPECT_FALSE(Inside(right, 0.2, 5));
  EXPECT_TRUE(Inside(right, 0.95, 8.9));
  EXPECT_TRUE(ReachesTop(right, scratch));
  EXPECT_EQ(SilhouetteWRange(right, scratch), std::make_pair(1.0, 9.0));
}

TEST(ChartNarrowingTest, LineEndingJustInsideTheChartLeavesTheTopOpenThere) {
  // A contour vertex on the face's viewing ray: the line starts at lambda 1e-14, its edge
  // before it was left out as vertical, so on (0, 1e-14) the sweep sees the corner's side up
  // to the top. The range must include the top, or a narrowed box cuts that sliver.
  ViewBuild build = Box(1, 9, true);
  build.lines = {Line(1e-14, 5, 1, 6)};
  std::vector<double> scratch;
  EXPECT_TRUE(Inside(build, 0.5e-14, 8.9));
  EXPECT_FALSE(Inside(build, 0.5, 8.9));
  EXPECT_TRUE(ReachesTop(build, scratch));
  EXPECT_EQ(SilhouetteWRange(build, scratch).second, 9.0);
}

TEST(ChartNarrowingTest, NarrowedBuildSeesTheSameSilhouetteInsideTheNewBox) {
  // A notch: inside below a rising line and above a falling one that cross the new box.
  ViewBuild build = Box(0, 10, false);
  build.lines = {Line(0, 1, 1, 9), Line(0, 8, 0.6, 4), Line(0.6, 4, 1, 9.5)};
  build.events = {{0.6, 4, 7, 8}, {0.3, 0.5, 5, 6}};
  const ViewBuild before = build;
  const double w_min = 3, w_max = 7;
  // The caller tests the new corner against the silhouette; here, the old build says.
  NarrowViewBuild(w_min, w_max, Inside(before, 1e-9, w_min), build);
  EXPECT_EQ(build.w_min, w_min);
  EXPECT_EQ(build.w_max, w_max);
  ASSERT_EQ(build.lines.size(), 3u);
  for (const ChartLine& line : build.lines) {
    EXPECT_GE(line.w_lo, w_min);
    EXPECT_LE(line.w_hi, w_max);
  }
  EXPECT_NEAR(build.lines[0].bottom_crossing, 0.25, 1e-12);  // w = 1 + 8 lambda = 3
  ASSERT_EQ(build.events.size(), 1u);
  EXPECT_EQ(build.events[0].lambda, 0.6);
  for (double lambda = 0.013; lambda < 1; lambda += 0.05) {
    for (double w = w_min + 0.01; w < w_max; w += 0.29)
      EXPECT_EQ(Inside(build, lambda, w), Inside(before, lambda, w)) << lambda << " " << w;
  }
}

TEST(ChartNarrowingTest, LinesOutsideTheNewBoxAreDropped) {
  ViewBuild build = Box(0, 10, true);
  build.lines = {Line(0, 1, 1, 1.5), Line(0, 8, 1, 9)};
  NarrowViewBuild(4, 6, true, build);
  EXPECT_TRUE(build.lines.empty());
  std::vector<double> scratch;
  EXPECT_EQ(SilhouetteWRange(build, scratch), std::make_pair(4.0, 6.0));
}

}  // namespace
}  // namespace silnet::aggregator

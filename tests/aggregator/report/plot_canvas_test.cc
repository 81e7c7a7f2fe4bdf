#include "aggregator/report/plot_canvas.h"

#include <gtest/gtest.h>

#include <cmath>

#include "aggregator/report/html_table.h"
#include "aggregator/report/report_statistics.h"

namespace silnet::aggregator {
namespace {

TEST(PlotCanvas, NiceTicksAreRoundAndCoverTheRange) {
  struct Case {
    double lo, hi;
  };
  for (const Case& c :
       {Case{0, 1}, Case{-3.7, 12.2}, Case{0.0012, 0.0047}, Case{-1e5, 2e5}, Case{5, 5.3}}) {
    const std::vector<double> ticks = NiceTicks(c.lo, c.hi, 5);
    ASSERT_GE(ticks.size(), 3u) << c.lo << " " << c.hi;
    ASSERT_LE(ticks.size(), 11u);
    const double step = ticks[1] - ticks[0];
    const double mantissa = step / std::pow(10.0, std::floor(std::log10(step)));
    EXPECT_TRUE(std::abs(mantissa - 1) < 1e-6 || std::abs(mantissa - 2) < 1e-6 ||
                std::abs(mantissa - 5) < 1e-6)
        << step;
    for (double t : ticks) {
      EXPECT_GE(t, c.lo - 1e-12);
      EXPECT_LE(t, c.hi + 1e-12);
      EXPECT_NEAR(std::remainder(t, step), 0.0, 1e-9 * step);
    }
    EXPECT_LT(ticks.front() - c.lo, step + 1e-12);
    EXPECT_LT(c.hi - ticks.back(), step + 1e-12);
  }
  EXPECT_TRUE(NiceTicks(1, 1).empty());
  EXPECT_EQ(TickLabel(0.30000000000000004), "0.3");
  EXPECT_EQ(TickLabel(-0.0), "0");
}

TEST(PlotCanvas, MapsDataToPixelsWithEqualAspect) {
  cv::Mat image = BlankImage(600, 400);
  PlotCanvas canvas(image, cv::Rect(100, 0, 500, 400));
  canvas.SetRanges(0, 10, 0, 1);
  canvas.MakeEqualAspect();
  const cv::Point2d a = canvas.ToPixel(0, 0), b = canvas.ToPixel(1, 1);
  EXPECT_NEAR(b.x - a.x, a.y - b.y, 1e-9);  // y grows upwards
  EXPECT_TRUE(canvas.Contains(0, 0));
  EXPECT_TRUE(canvas.Contains(10, 0.5));
  const cv::Rect plot = canvas.plot_area();
  EXPECT_GE(plot.x, 100);
  EXPECT_LE(plot.x + plot.width, 600);
  // Data outside the range is clipped to the plot area.
  canvas.Line(-100, -100, 100, 100, cv::Scalar(0, 0, 0), 3);
  cv::Mat outside = image(cv::Rect(0, 0, 100, 400)).clone();
  EXPECT_EQ(cv::countNonZero(outside.reshape(1) != 255), 0);
}

TEST(PlotCanvas, EscapesHtmlAndComputesStatistics) {
  EXPECT_EQ(EscapeHtml("<a href=\"x\">&'</a>"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;");
  HtmlTable table({"a<b"});
  EXPECT_NE(table.ToHtml("<none>").find("&lt;none&gt;"), std::string::npos);
  table.AddRow({"<td>"}, "bad");
  EXPECT_NE(table.ToHtml().find("<td>&lt;td&gt;</td>"), std::string::npos);
  EXPECT_NE(table.ToHtml().find("<th>a&lt;b</th>"), std::string::npos);
  EXPECT_DOUBLE_EQ(Median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4, 1, 2, 3}), 2.5);
  EXPECT_DOUBLE_EQ(Median({}), 0.0);
  EXPECT_DOUBLE_EQ(Rms({3, 4}), std::sqrt(12.5));
}

}  // namespace
}  // namespace silnet::aggregator

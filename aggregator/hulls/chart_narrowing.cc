#include "aggregator/hulls/chart_narrowing.h"

#include <algorithm>
#include <limits>

namespace silnet::aggregator {

// Along w = w_max the inside flips at every line's end and bottom crossing. (The contour edge
// left out as vertical where a line ends inside the box would flip it too; the sweep does not
// see it, and neither does this.)
bool ReachesTop(const ViewBuild& build, std::vector<double>& toggles) {
  bool inside = build.corner_inside;  // at lambda = 0+
  toggles.clear();
  for (const ChartLine& line : build.lines) {
    if (line.w_hi >= build.w_max) return true;  // the inside flips where it crosses the top
    if (line.lambda_lo > 0) {
      toggles.push_back(line.lambda_lo);
    } else {
      inside = !inside;
    }
    if (line.lambda_hi < 1) toggles.push_back(line.lambda_hi);
    if (line.bottom_crossing > 0) {
      toggles.push_back(line.bottom_crossing);
    } else if (line.bottom_crossing == 0) {
      inside = !inside;
    }
  }
  std::sort(toggles.begin(), toggles.end());
  double previous = 0;
  for (double lambda : toggles) {
    if (inside && lambda > previous) return true;
    inside = !inside;
    previous = lambda;
  }
  return inside && previous < 1;
}

// The silhouette's lowest point is on the bottom or on a line: a vertical piece of its outline
// runs between line ends or down to the bottom.
std::pair<double, double> SilhouetteWRange(const ViewBuild& build, std::vector<double>& toggles) {
  bool bottom = build.corner_inside;
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const ChartLine& line : build.lines) {
    low = std::min(low, line.w_lo);
    high = std::max(high, line.w_hi);
    bottom = bottom || line.bottom_crossing >= 0;
  }
  return {bottom ? build.w_min : low, ReachesTop(build, toggles) ? build.w_max : high};
}

void NarrowViewBuild(double w_min, double w_max, bool corner_inside, ViewBuild& build) {
  build.corner_inside = corner_inside;
  std::erase_if(build.lines, [&](ChartLine& line) {
    if (line.w_hi < w_min || line.w_lo > w_max) return true;
    line.bottom_crossing = -1;
    const bool rising = line.slope > 0;
    if (line.w_lo < w_min) {
      const double lambda =
          std::clamp((w_min - line.intercept) / line.slope, line.lambda_lo, line.lambda_hi);
      (rising ? line.lambda_lo : line.lambda_hi) = lambda;
      line.w_lo = w_min;
      line.bottom_crossing = lambda;
    }
    if (line.w_hi > w_max) {
      const double lambda =
          std::clamp((w_max - line.intercept) / line.slope, line.lambda_lo, line.lambda_hi);
      (rising ? line.lambda_hi : line.lambda_lo) = lambda;
      line.w_hi = w_max;
    }
    return false;
  });
  std::erase_if(build.events,
                [&](const ChartEvent& event) { return event.w < w_min || event.w > w_max; });
  build.w_min = w_min;
  build.w_max = w_max;
}

}  // namespace silnet::aggregator

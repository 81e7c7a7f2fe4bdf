#pragma once
// Narrowing a cone face's chart to its region (the exact hull's speed-up): one other view's
// lines in the chart, the inverse-depth range its silhouette covers there as the face's sweep
// sees it, and those lines cut down to a smaller chart box. The region lies inside every
// view's range, so the chart box can shrink to their intersection before the sweep.

#include <utility>
#include <vector>

#include "aggregator/hulls/cone_face_region.h"

namespace silnet::aggregator {

// One other view's lines and contour-vertex events in a face's chart, built for the chart box
// lambda in [0, 1], w in [w_min, w_max]; `corner_inside` says whether the box's corner
// (0, w_min) lies in that view's silhouette. The sweep's view of the silhouette at (lambda, w):
// `corner_inside`, flipped by every bottom crossing before lambda and every line spanning
// lambda below w.
struct ViewBuild {
  std::vector<ChartLine> lines;
  std::vector<ChartEvent> events;
  bool corner_inside = false;
  double w_min = 0, w_max = 0;
};

// True if the sweep sees the silhouette reach the box's top (w = w_max) on some lambda
// interval of positive length. `toggles` is scratch.
bool ReachesTop(const ViewBuild& build, std::vector<double>& toggles);

// The w-range the sweep sees the silhouette cover inside the box: from w_min if it reaches
// the bottom, otherwise from its lines' lowest w; to w_max if it reaches the top, otherwise
// to their highest w. Empty (first > second) if it covers nothing. `toggles` is scratch.
std::pair<double, double> SilhouetteWRange(const ViewBuild& build, std::vector<double>& toggles);

// Cuts `build` down to the box w in [w_min, w_max] inside the one it was built for:
// lines outside dropped, the others cut at the new bottom and top (their bottom crossings
// moved there), events outside dropped, `corner_inside` (whether (0, w_min) lies in the
// silhouette, which the caller tests) taken as the new corner's. The lines and events are
// those building the view for the new box would give.
void NarrowViewBuild(double w_min, double w_max, bool corner_inside, ViewBuild& build);

}  // namespace silnet::aggregator

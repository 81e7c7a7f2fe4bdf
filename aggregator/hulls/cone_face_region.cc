#include "aggregator/hulls/cone_face_region.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <limits>
#include <utility>

#include "aggregator/hulls/chart_narrowing.h"

namespace silnet::aggregator {
namespace {

constexpr double kLambdaEpsilon = 1e-12;

// Sides of the chart box, in the order of the half-planes below.
enum ChartSide { kLambdaZero = 0, kLambdaOne = 1, kBottom = 2, kTop = 3, kVertex = -1 };

// The chart seen from one other camera: the homography chart -> image and the chart box's
// image as four half-planes (inside where all are >= 0).
struct ViewMapping {
  Eigen::Matrix3d to_image;
  Eigen::Matrix3d to_chart;
  std::array<Eigen::Vector3d, 4> sides;
};

// The chart point of a pixel inside the box's image.
Eigen::Vector2d ChartPoint(const ViewMapping& mapping, const Eigen::Vector2d& pixel) {
  const Eigen::Vector3d c = mapping.to_chart * pixel.homogeneous();
  return {c.x() / c.z(), c.y() / c.z()};
}

// The chart endpoint where a clipped edge ends, snapped onto the box side that clipped it.
Eigen::Vector2d ClippedEndpoint(const ViewMapping& mapping, const Eigen::Vector2d& pixel, int side,
                                double w_min, double w_max) {
  Eigen::Vector2d c = ChartPoint(mapping, pixel);
  if (side == kLambdaZero) c.x() = 0;
  if (side == kLambdaOne) c.x() = 1;
  if (side == kBottom) c.y() = w_min;
  if (side == kTop) c.y() = w_max;
  return c;
}

// The homography from the face's chart (lambda, w, 1) to `view`'s undistorted image.
Eigen::Matrix3d ChartToImage(const ConePlaneSet& set, int view, const FaceRegion& region) {
  const Matrix34d& P = set.Projection(view);
  const Eigen::Matrix3d M = P.leftCols<3>();
  Eigen::Matrix3d to_image;
  to_image.col(0) = M * (region.d_q - region.d_p);
  to_image.col(1) = P * region.centre.homogeneous();
  to_image.col(2) = M * region.d_p;
  return to_image;
}

// True if an undistorted pixel lies inside `view`'s silhouette; outside its bounding octagon
// without the polygon test.
bool InsideSilhouette(const ConePlaneSet& set, int view, const Eigen::Vector2d& pixel) {
  for (const Eigen::Vector3d& side : set.BoundingOctagon(view)) {
    if (side.dot(pixel.homogeneous()) < 0) return false;
  }
  return set.Contains(view, pixel);
}

// Builds the lines of one other view's contour edges that cross the chart box (the region's
// current w-range) into `lines`, and the events they cause into `events`. Returns false if the
// box is not entirely in front of that camera.
bool AddViewLines(const ConePlaneSet& set, int face_view, int view, const FaceRegion& region,
                  bool& corner_inside, std::vector<int>& candidates, std::vector<ChartLine>& lines,
                  std::vector<ChartEvent>& events) {
  ViewMapping mapping;
  mapping.to_image = ChartToImage(set, view, region);
  mapping.to_chart = mapping.to_image.inverse();
  const auto image_of = [&](double lambda, double w) {
    return Eigen::Vector3d(mapping.to_image * Eigen::Vector3d(lambda, w, 1));
  };
  const std::array<Eigen::Vector3d, 4> corners = {
      image_of(0, region.w_min), image_of(1, region.w_min), image_of(1, region.w_max),
      image_of(0, region.w_max)};
  for (const Eigen::Vector3d& corner : corners) {
    if (!(corner.z() > 0)) return false;
  }
  const Eigen::Vector3d centre = image_of(0.5, 0.5 * (region.w_min + region.w_max));
  const std::array<std::pair<int, int>, 4> side_corners = {{{0, 3}, {1, 2}, {0, 1}, {3, 2}}};
  for (size_t s = 0; s < 4; ++s) {
    const Eigen::Vector3d a = corners[static_cast<size_t>(side_corners[s].first)] /
                              corners[static_cast<size_t>(side_corners[s].first)].z();
    const Eigen::Vector3d b = corners[static_cast<size_t>(side_corners[s].second)] /
                              corners[static_cast<size_t>(side_corners[s].second)].z();
    Eigen::Vector3d line = a.cross(b);
    if (line.dot(centre / centre.z()) < 0) line = -line;
    mapping.sides[s] = line;
  }
  corner_inside = InsideSilhouette(set, view, corners[0].hnormalized());

  candidates.clear();
  set.CandidateEdges(face_view, view, region.d_p, region.d_q, candidates);
  // The candidates share the chart's lambda range in epipolar angle; most lie beyond its
  // bottom or top, which are tested first.
  const auto beyond_depth_range = [&](const ConePlane& plane) {
    for (const int s : {kBottom, kTop}) {
      const Eigen::Vector3d& side = mapping.sides[static_cast<size_t>(s)];
      if (side.dot(plane.p.homogeneous()) < 0 && side.dot(plane.q.homogeneous()) < 0) return true;
    }
    return false;
  };
  for (int index : candidates) {
    const ConePlane& plane = set.Plane(index);
    if (beyond_depth_range(plane)) continue;
    double t0 = 0, t1 = 1;
    int side0 = kVertex, side1 = kVertex;
    bool rejected = false;
    for (int s = 0; s < 4 && !rejected; ++s) {
      const double hu = mapping.sides[static_cast<size_t>(s)].dot(plane.p.homogeneous());
      const double hv = mapping.sides[static_cast<size_t>(s)].dot(plane.q.homogeneous());
      if (hu < 0 && hv < 0) {
        rejected = true;
      } else if (hu < 0) {
        const double t = hu / (hu - hv);
        if (t > t0) t0 = t, side0 = s;
      } else if (hv < 0) {
        const double t = hu / (hu - hv);
        if (t < t1) t1 = t, side1 = s;
      }
    }
    if (rejected || t0 >= t1) continue;
    const Eigen::Vector2d a = ClippedEndpoint(mapping, plane.p + t0 * (plane.q - plane.p), side0,
                                              region.w_min, region.w_max);
    const Eigen::Vector2d b = ClippedEndpoint(mapping, plane.p + t1 * (plane.q - plane.p), side1,
                                              region.w_min, region.w_max);
    ChartLine line;
    line.plane = index;
    line.view = view;
    line.coefficients =
        mapping.to_image.transpose() * plane.p.homogeneous().cross(plane.q.homogeneous());
    line.slope = -line.coefficients.x() / line.coefficients.y();
    line.intercept = -line.coefficients.z() / line.coefficients.y();
    line.lambda_lo = std::min(a.x(), b.x());
    line.lambda_hi = std::max(a.x(), b.x());
    line.w_lo = std::min(a.y(), b.y());
    line.w_hi = std::max(a.y(), b.y());
    if (side0 == kBottom) line.bottom_crossing = a.x();
    if (side1 == kBottom) line.bottom_crossing = b.x();
    if (line.lambda_hi - line.lambda_lo <= kLambdaEpsilon) continue;
    lines.push_back(line);
    const auto add_event = [&](const Eigen::Vector2d& end, int side, int neighbour) {
      if (end.x() <= 0 || end.x() >= 1 || side != kVertex) return;
      events.push_back({end.x(), end.y(), index, neighbour});
    };
    add_event(a, side0, plane.prev);
    add_event(b, side1, plane.next);
  }
  return true;
}

// An interval bound: w and the line there (-1 for the chart box).
using Bound = std::pair<double, int>;

// One view's lines: FaceRegion::lines[begin, end).
struct LineRange {
  int begin = 0, end = 0;
};

// Buffers a face's computation reuses (one set per thread).
struct FaceScratch {
  std::vector<int> candidates;
  std::vector<std::pair<double, int>> order;  // lines by their lowest w
  std::vector<Bound> bounds, crossings, view_bounds, merged;
  std::vector<double> cuts;
  std::vector<LineRange> view_lines;
  std::vector<char> corner_inside;
  int last_rejecting = -1;        // the view InsideOtherViews tries first
  std::vector<ViewBuild> builds;  // per view
  std::vector<double> narrowing;  // per view: its share of the last face's chart w-range
  std::vector<int> view_order;    // the other views, most narrowing first
  std::vector<int> bounding;      // the other views with lines in the chart (the rest hold it)
  int failed_view = -1;           // the camera a face's box is not in front of
};

// The w-intervals inside one view's silhouette along the vertical chart line at `lambda`,
// into `bounds`: entries 2k and 2k + 1 bound the k-th interval. `crossings` is scratch.
void ViewIntervals(const FaceRegion& region, LineRange lines, bool inside, double lambda,
                   std::vector<Bound>& crossings, std::vector<Bound>& bounds) {
  crossings.clear();
  bounds.clear();
  for (int index = lines.begin; index < lines.end; ++index) {
    const ChartLine& line = region.lines[static_cast<size_t>(index)];
    inside ^= line.bottom_crossing >= 0 && line.bottom_crossing < lambda;
    if (line.lambda_lo < lambda && lambda < line.lambda_hi) {
      const double w = line.WAt(lambda);
      if (w > region.w_min && w < region.w_max) crossings.emplace_back(w, index);
    }
  }
  std::sort(crossings.begin(), crossings.end());
  if (inside) bounds.emplace_back(region.w_min, -1);
  for (const Bound& crossing : crossings) {
    bounds.push_back(crossing);
    inside = !inside;
  }
  if (inside) bounds.emplace_back(region.w_max, -1);
}

// The intersection of interval lists `a` and `b` (format above), into `out`.
void IntersectIntervals(const std::vector<Bound>& a, const std::vector<Bound>& b,
                        std::vector<Bound>& out) {
  out.clear();
  size_t i = 0, j = 0;
  while (i + 1 < a.size() && j + 1 < b.size()) {
    const Bound& lo = a[i].first > b[j].first ? a[i] : b[j];
    const Bound& hi = a[i + 1].first < b[j + 1].first ? a[i + 1] : b[j + 1];
    if (lo.first < hi.first) {
      out.push_back(lo);
      out.push_back(hi);
    }
    if (a[i + 1].first < b[j + 1].first) {
      i += 2;
    } else {
      j += 2;
    }
  }
}

// The lambda where two lines cross inside both their spans, or -1.
double Crossing(const ChartLine& f, const ChartLine& g) {
  const double det =
      f.coefficients.x() * g.coefficients.y() - f.coefficients.y() * g.coefficients.x();
  if (det == 0) return -1;
  const double lambda =
      (f.coefficients.y() * g.coefficients.z() - f.coefficients.z() * g.coefficients.y()) / det;
  if (lambda <= std::max(f.lambda_lo, g.lambda_lo) || lambda >= std::min(f.lambda_hi, g.lambda_hi))
    return -1;
  return lambda;
}

// True if chart point (lambda, w) lies inside the silhouette of the view with these lines
// (`inside`: whether the chart's corner (0, w_min) is). Counts crossings without branches.
bool InsideView(const FaceRegion& region, LineRange lines, bool inside, double lambda, double w) {
  unsigned parity = inside ? 1u : 0u;
  for (int index = lines.begin; index < lines.end; ++index) {
    const ChartLine& line = region.lines[static_cast<size_t>(index)];
    parity ^= static_cast<unsigned>(line.bottom_crossing >= 0) &
              static_cast<unsigned>(line.bottom_crossing < lambda);
    parity ^= static_cast<unsigned>(line.lambda_lo < lambda) &
              static_cast<unsigned>(lambda < line.lambda_hi) &
              static_cast<unsigned>(line.WAt(lambda) < w);
  }
  return parity != 0;
}

// True if chart point (lambda, w) lies inside every view's silhouette but views `skip_a` and
// `skip_b`. The view that last rejected a point is tried first: it usually rejects the next.
bool InsideOtherViews(const FaceRegion& region, FaceScratch& scratch, int skip_a, int skip_b,
                      double lambda, double w) {
  const auto outside = [&](int view) {
    const auto v = static_cast<size_t>(view);
    return view != skip_a && view != skip_b &&
           !InsideView(region, scratch.view_lines[v], scratch.corner_inside[v] != 0, lambda, w);
  };
  const int first = scratch.last_rejecting;
  if (first >= 0 && outside(first)) return false;
  for (const int view : scratch.bounding) {
    if (view != first && outside(view)) {
      scratch.last_rejecting = view;
      return false;
    }
  }
  return true;
}

// Adds the crossings of two views' lines that lie inside every other view: the only
// crossings where the region can gain or lose a vertex (triple points, and the lambdas
// where an interval is born or dies).
void AddCrossingEvents(FaceRegion& region, FaceScratch& scratch) {
  std::vector<std::pair<double, int>>& by_w = scratch.order;
  const std::vector<ChartLine>& lines = region.lines;
  by_w.resize(lines.size());
  for (size_t l = 0; l < by_w.size(); ++l)
    by_w[l] = {lines[l].w_lo, static_cast<int>(l)};
  std::sort(by_w.begin(), by_w.end());
  for (size_t f = 0; f < by_w.size(); ++f) {
    const ChartLine& first = lines[static_cast<size_t>(by_w[f].second)];
    for (size_t g = f + 1; g < by_w.size(); ++g) {
      const ChartLine& second = lines[static_cast<size_t>(by_w[g].second)];
      if (second.w_lo > first.w_hi) break;
      if (first.view == second.view) continue;
      const double lambda = Crossing(first, second);
      if (lambda <= 0 || lambda >= 1) continue;
      const double w = first.WAt(lambda);
      if (InsideOtherViews(region, scratch, first.view, second.view, lambda, w))
        region.events.push_back({lambda, w, first.plane, second.plane});
    }
  }
}

// The chart box is narrowed to the region's w-range found so far (with this share of it as a
// margin on each side) when that is at most kNarrowingWorth of the box.
constexpr double kNarrowingMargin = 1e-3;
// and at least this share of the box's w-range before narrowing.
constexpr double kLeastNarrowingMargin = 1e-6;
constexpr double kNarrowingWorth = 0.9;

// What BuildViewLines found.
enum class BuildOutcome { kBuilt, kEmpty, kBehindCamera };

// Builds one other view's lines and events into scratch.builds[view] for the region's box.
BuildOutcome BuildView(const ConePlaneSet& set, int face_view, int view, const FaceRegion& region,
                       FaceScratch& scratch) {
  ViewBuild& build = scratch.builds[static_cast<size_t>(view)];
  build.lines.clear();
  build.events.clear();
  build.w_min = region.w_min;
  build.w_max = region.w_max;
  if (!AddViewLines(set, face_view, view, region, build.corner_inside, scratch.candidates,
                    build.lines, build.events)) {
    scratch.failed_view = view;
    return BuildOutcome::kBehindCamera;
  }
  // With no line and its corner outside, the face lies entirely outside that view's cone.
  return build.lines.empty() && !build.corner_inside ? BuildOutcome::kEmpty : BuildOutcome::kBuilt;
}

// Builds every other view's lines into region.lines (scratch.view_lines giving each view's
// range, scratch.corner_inside whether the chart's corner lies in its silhouette) and their
// contour-vertex events into region.events. The views are taken in the order that narrowed the
// previous face most; each narrows the chart's w-range to its silhouette's, and the box is
// shrunk to that range (the region lies inside it) so the following views' lines, crossings
// and intervals are few; views built for a wider box are narrowed to the final one.
BuildOutcome BuildViewLines(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                            int face_view, bool narrow, FaceRegion& region, FaceScratch& scratch) {
  const size_t views = cameras.size();
  scratch.builds.resize(views);
  if (scratch.narrowing.size() != views) scratch.narrowing.assign(views, 1.0);
  scratch.view_order.clear();
  for (size_t v = 0; v < views; ++v) {
    if (static_cast<int>(v) != face_view) scratch.view_order.push_back(static_cast<int>(v));
  }
  std::stable_sort(scratch.view_order.begin(), scratch.view_order.end(), [&](int a, int b) {
    return scratch.narrowing[static_cast<size_t>(a)] < scratch.narrowing[static_cast<size_t>(b)];
  });
  const double full_min = region.w_min, full_max = region.w_max;
  double low = full_min, high = full_max;
  const double least_margin = kLeastNarrowingMargin * (high - low);
  for (int view : scratch.view_order) {
    const BuildOutcome outcome = BuildView(set, face_view, view, region, scratch);
    if (outcome != BuildOutcome::kBuilt) return outcome;
    const ViewBuild& build = scratch.builds[static_cast<size_t>(view)];
    const auto [a, b] = SilhouetteWRange(build, scratch.cuts);
    scratch.narrowing[static_cast<size_t>(view)] = (b - a) / (build.w_max - build.w_min);
    low = std::max(low, a);
    high = std::min(high, b);
    if (!(low < high)) return BuildOutcome::kEmpty;
    const double margin = kNarrowingMargin * (high - low) + least_margin;
    if (narrow && high - low + 2 * margin <= kNarrowingWorth * (region.w_max - region.w_min)) {
      region.w_min = std::max(region.w_min, low - margin);
      region.w_max = std::min(region.w_max, high + margin);
    }
  }
  // The final box from the final bounds alone (they do not depend on the order the views were
  // built in), so the region does not depend on which faces a thread computed before.
  if (region.w_min != full_min || region.w_max != full_max) {
    const double margin = kNarrowingMargin * (high - low) + least_margin;
    region.w_min = std::max(full_min, low - margin);
    region.w_max = std::min(full_max, high + margin);
  }
  scratch.view_lines.assign(views, LineRange{});
  scratch.bounding.clear();
  scratch.corner_inside.assign(views, 1);
  region.lines.clear();
  region.events.clear();
  for (int view : scratch.view_order) {
    const auto v = static_cast<size_t>(view);
    ViewBuild& build = scratch.builds[v];
    // A view without lines held the whole box it was built for (the face would be empty had
    // it held none of it), so it holds the final one too.
    if (build.lines.empty() || (build.w_min == region.w_min && build.w_max == region.w_max))
      continue;
    const Eigen::Vector3d corner =
        ChartToImage(set, view, region) * Eigen::Vector3d(0, region.w_min, 1);
    NarrowViewBuild(region.w_min, region.w_max, InsideSilhouette(set, view, corner.hnormalized()),
                    build);
    if (build.lines.empty() && !build.corner_inside) return BuildOutcome::kEmpty;
  }
  size_t line_count = 0, event_count = 0;
  for (int view : scratch.view_order) {
    line_count += scratch.builds[static_cast<size_t>(view)].lines.size();
    event_count += scratch.builds[static_cast<size_t>(view)].events.size();
  }
  region.lines.reserve(line_count);
  region.events.reserve(event_count);
  for (size_t v = 0; v < views; ++v) {
    if (static_cast<int>(v) == face_view) continue;
    const ViewBuild& build = scratch.builds[v];
    const int first = static_cast<int>(region.lines.size());
    region.lines.insert(region.lines.end(), build.lines.begin(), build.lines.end());
    region.events.insert(region.events.end(), build.events.begin(), build.events.end());
    scratch.view_lines[v] = {first, static_cast<int>(region.lines.size())};
    scratch.corner_inside[v] = build.corner_inside ? 1 : 0;
    // A view without lines holds the whole chart (one whose corner lies outside too left the
    // face empty): only the others bound the region.
    if (!build.lines.empty()) scratch.bounding.push_back(static_cast<int>(v));
  }
  scratch.last_rejecting = -1;
  return BuildOutcome::kBuilt;
}

// The face's region, in the chart box narrowed to it as the views are built if `narrow` (and
// computed again in the full box if it reaches the narrowed one).
FaceRegion RegionOfFace(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                        int plane_index, const WorldBox& box, bool narrow) {
  FaceRegion region;
  region.plane = plane_index;
  const ConePlane& plane = set.Plane(plane_index);
  const CameraModel& camera = cameras[static_cast<size_t>(plane.view)];
  region.centre = camera.Center();
  region.d_p = set.RayThroughP(plane_index);
  region.d_q = set.RayThroughP(plane.next);
  double depth_min = std::numeric_limits<double>::infinity(), depth_max = 0;
  for (int k = 0; k < 8; ++k) {
    const double depth =
        (camera.R * box.corner(static_cast<WorldBox::CornerType>(k)) + camera.t).z();
    depth_min = std::min(depth_min, depth);
    depth_max = std::max(depth_max, depth);
  }
  if (!(depth_min > 0)) {
    region.reason = fmt::format("camera {} is inside or behind the hull's bounds", camera.id);
    return region;
  }
  region.w_min = 1 / depth_max;
  region.w_max = 1 / depth_min;

  thread_local FaceScratch scratch;
  switch (BuildViewLines(cameras, set, plane.view, narrow, region, scratch)) {
    case BuildOutcome::kBehindCamera:
      region.reason = fmt::format("the hull's bounds are not in front of camera {}",
                                  cameras[static_cast<size_t>(scratch.failed_view)].id);
      return region;
    case BuildOutcome::kEmpty:
      region.success = true;  // the face lies outside some camera's cone
      return region;
    case BuildOutcome::kBuilt:
      break;
  }

  // A contour vertex of another view changes the region only if it lies inside the rest.
  std::erase_if(region.events, [&](const ChartEvent& event) {
    return !InsideOtherViews(region, scratch, set.Plane(event.first).view, plane.view, event.lambda,
                             event.w);
  });
  AddCrossingEvents(region, scratch);
  std::vector<double>& cuts = scratch.cuts;
  cuts.assign({0.0, 1.0});
  for (const ChartEvent& event : region.events)
    cuts.push_back(event.lambda);
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  std::vector<Bound>& bounds = scratch.bounds;
  region.slabs.reserve(cuts.size() - 1);
  region.intervals.reserve(2 * (cuts.size() - 1));
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k], b = cuts[k + 1];
    const double middle = 0.5 * (a + b);
    bounds.assign({{region.w_min, -1}, {region.w_max, -1}});
    for (size_t i = 0; i < scratch.bounding.size() && !bounds.empty(); ++i) {
      const auto v = static_cast<size_t>(scratch.bounding[i]);
      ViewIntervals(region, scratch.view_lines[v], scratch.corner_inside[v] != 0, middle,
                    scratch.crossings, scratch.view_bounds);
      IntersectIntervals(bounds, scratch.view_bounds, scratch.merged);
      bounds.swap(scratch.merged);
    }
    for (const auto& bound : bounds) {
      if (bound.second >= 0) continue;
      // Reaching a narrowed box is a sliver slab near the chart's side in which a contour
      // vertex on the face's viewing ray left another view's silhouette open (its edge has no
      // lambda-span); the full box keeps the side's lines.
      if (narrow) return RegionOfFace(cameras, set, plane_index, box, false);
      region.reason = "the hull reaches the bounds it was computed in";
      return region;
    }
    const auto same_intervals = [&](const ChartSlab& slab) {
      if (2 * static_cast<size_t>(slab.count) != bounds.size()) return false;
      for (size_t i = 0; i < static_cast<size_t>(slab.count); ++i) {
        const std::pair<int, int>& interval = region.intervals[static_cast<size_t>(slab.first) + i];
        if (interval.first != bounds[2 * i].second || interval.second != bounds[2 * i + 1].second)
          return false;
      }
      return true;
    };
    if (!region.slabs.empty() && same_intervals(region.slabs.back())) {
      region.slabs.back().lambda_b = b;
      continue;
    }
    region.slabs.push_back(
        {a, b, static_cast<int>(region.intervals.size()), static_cast<int>(bounds.size() / 2)});
    for (size_t i = 0; i + 1 < bounds.size(); i += 2)
      region.intervals.emplace_back(bounds[i].second, bounds[i + 1].second);
  }
  std::sort(region.events.begin(), region.events.end(),
            [](const ChartEvent& x, const ChartEvent& y) { return x.lambda < y.lambda; });
  region.success = true;
  return region;
}

}  // namespace

FaceRegion ComputeFaceRegion(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                             int plane_index, const WorldBox& box) {
  return RegionOfFace(cameras, set, plane_index, box, true);
}

}  // namespace silnet::aggregator

#include "aggregator/stereo/uncoverable_pixels.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "aggregator/hulls/polyhedral_hull.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// Parameter intervals [lo, hi], sorted and disjoint.
using Intervals = std::vector<std::pair<double, double>>;

// Largest sample spacing along the ray's image in a view, pixels.
constexpr double kSampleStepPx = 0.5;
// Nearest depth in front of a camera a ray point is taken at, metres.
constexpr double kMinDepth = 1e-6;

// Narrows [t0, t1] to where a + b t >= 0.
void Restrict(double a, double b, double& t0, double& t1) {
  if (b > 0) {
    t0 = std::max(t0, -a / b);
  } else if (b < 0) {
    t1 = std::min(t1, -a / b);
  } else if (a < 0) {
    t1 = -std::numeric_limits<double>::infinity();
  }
}

// The intersection of two interval lists.
Intervals Intersect(const Intervals& a, const Intervals& b) {
  Intervals out;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const double lo = std::max(a[i].first, b[j].first);
    const double hi = std::min(a[i].second, b[j].second);
    if (lo <= hi) out.emplace_back(lo, hi);
    (a[i].second < b[j].second ? i : j) += 1;
  }
  return out;
}

// The ray's image in one view between the ray's ends: homogeneous ends, their depths, and the
// projective map from the image segment's fraction s to the ray's fraction alpha.
struct RayImage {
  Eigen::Vector2d u0, u1;
  double z0 = 1, z1 = 1;

  Eigen::Vector2d At(double s) const { return u0 + s * (u1 - u0); }
  double Alpha(double s) const { return s * z0 / ((1 - s) * z1 + s * z0); }
};

// The fractions s of the image segment inside the image rectangle [-0.5, size - 0.5]
// (Liang-Barsky), or an empty pair (lo > hi).
std::pair<double, double> InsideImage(const RayImage& image, int width, int height) {
  double lo = 0, hi = 1;
  const Eigen::Vector2d d = image.u1 - image.u0;
  const double limits[2][2] = {{-0.5, width - 0.5}, {-0.5, height - 0.5}};
  for (int axis = 0; axis < 2; ++axis) {
    const double start = image.u0[axis], delta = d[axis];
    for (int side = 0; side < 2; ++side) {
      // side 0: start + s delta >= min; side 1: start + s delta <= max.
      const double a = side == 0 ? start - limits[axis][0] : limits[axis][1] - start;
      const double b = side == 0 ? delta : -delta;
      Restrict(a, b, lo, hi);
    }
  }
  return {lo, hi};
}

// The ray fractions alpha where the ray lies inside a view's grown silhouette (outside the
// image: inside if `border_cut`, else outside), each stretch widened by half a sample.
Intervals StretchesInside(const RayImage& image, const cv::Mat& grown, bool border_cut) {
  Intervals out;
  const auto add = [&](double s_lo, double s_hi) {
    const double lo = image.Alpha(std::clamp(s_lo, 0.0, 1.0));
    const double hi = image.Alpha(std::clamp(s_hi, 0.0, 1.0));
    if (!out.empty() && lo <= out.back().second)
      out.back().second = std::max(out.back().second, hi);
    else
      out.emplace_back(lo, hi);
  };
  const auto [in_lo, in_hi] = InsideImage(image, grown.cols, grown.rows);
  if (!(in_lo <= in_hi)) {
    if (border_cut) out.emplace_back(0.0, 1.0);
    return out;
  }
  if (border_cut && in_lo > 0) add(0, in_lo);
  const double length = (image.At(in_hi) - image.At(in_lo)).norm();
  const int samples = std::max(2, static_cast<int>(std::ceil(length / kSampleStepPx)) + 1);
  const double ds = (in_hi - in_lo) / (samples - 1);
  int run_start = -1;
  for (int k = 0; k <= samples; ++k) {
    bool inside = false;
    if (k < samples) {
      const Eigen::Vector2d p = image.At(in_lo + k * ds);
      const int x = std::clamp(static_cast<int>(std::lround(p.x())), 0, grown.cols - 1);
      const int y = std::clamp(static_cast<int>(std::lround(p.y())), 0, grown.rows - 1);
      inside = grown.at<uint8_t>(y, x) != 0;
    }
    if (inside && run_start < 0) run_start = k;
    if (!inside && run_start >= 0) {
      add(in_lo + (run_start - 0.5) * ds, in_lo + (k - 0.5) * ds);
      run_start = -1;
    }
  }
  if (border_cut && in_hi < 1) add(in_hi, 1);
  return out;
}

}  // namespace

GrownSilhouettes GrowSilhouettes(const std::vector<StereoView>& views, double margin_px) {
  SILNET_CHECK(margin_px >= 0);
  GrownSilhouettes out;
  for (const StereoView& view : views) {
    SILNET_CHECK(view.mask.type() == CV_8UC1 && !view.mask.empty());
    cv::Mat depth_out;
    cv::distanceTransform(view.mask == 0, depth_out, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
    out.grown.push_back(depth_out < static_cast<float>(margin_px + 0.5));
    out.border_cut.push_back(TouchesBorder(view.mask));
    out.projections.push_back(view.camera.ProjectionMatrix());
  }
  return out;
}

Eigen::Vector3d RayReach::NearestPoint(const Eigen::Vector3d& x) const {
  SILNET_CHECK(!stretches.empty());
  const double along = (x - origin).dot(direction);
  double best = stretches.front().first, best_gap = std::numeric_limits<double>::infinity();
  for (const auto& [lo, hi] : stretches) {
    const double t = std::clamp(along, lo, hi);
    if (std::abs(t - along) < best_gap) {
      best_gap = std::abs(t - along);
      best = t;
    }
  }
  return origin + best * direction;
}

RayReach CoverableReach(const std::vector<StereoView>& views, const GrownSilhouettes& grown,
                        size_t v, const Eigen::Vector2d& pixel) {
  SILNET_CHECK(v < views.size() && grown.grown.size() == views.size());
  const CameraModel& camera = views[v].camera;
  RayReach out;
  out.origin = camera.Center();
  out.direction = camera.R.transpose() * camera.PixelRay(pixel).normalized();
  const Eigen::Vector3d& origin = out.origin;
  const Eigen::Vector3d& direction = out.direction;
  // Homogeneous image of the ray, h0 + t h1, in every other view; the ray clipped to where it
  // lies in front of each and inside the image of each view the border does not cut.
  const double infinity = std::numeric_limits<double>::infinity();
  double t0 = 0, t1 = infinity;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> homogeneous(views.size());
  for (size_t j = 0; j < views.size(); ++j) {
    if (j == v) continue;
    const Matrix34d& P = grown.projections[j];
    const Eigen::Vector3d h0 = P * origin.homogeneous();
    const Eigen::Vector3d h1 = P.leftCols<3>() * direction;
    homogeneous[j] = {h0, h1};
    Restrict(h0.z() - kMinDepth, h1.z(), t0, t1);
    if (grown.border_cut[j]) continue;
    const double width = views[j].mask.cols, height = views[j].mask.rows;
    Restrict(h0.x() + 0.5 * h0.z(), h1.x() + 0.5 * h1.z(), t0, t1);
    Restrict((width - 0.5) * h0.z() - h0.x(), (width - 0.5) * h1.z() - h1.x(), t0, t1);
    Restrict(h0.y() + 0.5 * h0.z(), h1.y() + 0.5 * h1.z(), t0, t1);
    Restrict((height - 0.5) * h0.z() - h0.y(), (height - 0.5) * h1.z() - h1.y(), t0, t1);
  }
  if (!std::isfinite(t1)) {  // no view bounds the ray (or one excludes it)
    if (t1 > 0) out.stretches.emplace_back(t0, t1);
    return out;
  }
  if (!(t0 < t1)) return out;
  Intervals reach = {{0.0, 1.0}};
  for (size_t j = 0; j < views.size() && !reach.empty(); ++j) {
    if (j == v) continue;
    const auto& [h0, h1] = homogeneous[j];
    const Eigen::Vector3d a = h0 + t0 * h1, b = h0 + t1 * h1;
    const RayImage image{a.hnormalized(), b.hnormalized(), a.z(), b.z()};
    reach = Intersect(reach, StretchesInside(image, grown.grown[j], grown.border_cut[j]));
  }
  // The fractions of [t0, t1] as distances along the ray.
  for (const auto& [lo, hi] : reach)
    out.stretches.emplace_back(t0 + lo * (t1 - t0), t0 + hi * (t1 - t0));
  return out;
}

bool PixelCoverable(const std::vector<StereoView>& views, const GrownSilhouettes& grown, size_t v,
                    int x, int y) {
  return !CoverableReach(views, grown, v, {static_cast<double>(x), static_cast<double>(y)})
              .stretches.empty();
}

size_t CountUncoverable(const std::vector<StereoView>& views, const GrownSilhouettes& grown,
                        size_t v, const cv::Mat& pixels) {
  SILNET_CHECK(pixels.type() == CV_8UC1 && pixels.size() == views[v].mask.size());
  size_t count = 0;
  for (int y = 0; y < pixels.rows; ++y) {
    const uint8_t* row = pixels.ptr<uint8_t>(y);
    for (int x = 0; x < pixels.cols; ++x)
      if (row[x] != 0 && !PixelCoverable(views, grown, v, x, y)) ++count;
  }
  return count;
}

}  // namespace silnet::aggregator

#include "aggregator/report/network_plot.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "aggregator/report/plot_canvas.h"
#include "aggregator/report/report_statistics.h"

namespace silnet::aggregator {
namespace {

constexpr size_t kMaxPlottedPoints = 20000;

std::vector<size_t> PlacedCameras(const NetworkCalibration& calibration) {
  std::vector<size_t> placed;
  for (size_t i = 0; i < calibration.cameras.size(); ++i) {
    if (IsPlaced(calibration, i) && calibration.cameras[i].Center().allFinite())
      placed.push_back(i);
  }
  return placed;
}

// Any unit vector perpendicular to `v` (unit).
Eigen::Vector3d Perpendicular(const Eigen::Vector3d& v) {
  const Eigen::Vector3d other =
      std::abs(v.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return v.cross(other).normalized();
}

// The subsampled inlier frontier points.
std::vector<Eigen::Vector3d> PlottedPoints(const NetworkCalibration& calibration) {
  std::vector<Eigen::Vector3d> points;
  for (const FrontierPoint& p : calibration.points) {
    if (p.inlier && p.X.allFinite()) points.push_back(p.X);
  }
  if (points.size() <= kMaxPlottedPoints) return points;
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(kMaxPlottedPoints);
  for (size_t k = 0; k < kMaxPlottedPoints; ++k)
    kept.push_back(points[k * points.size() / kMaxPlottedPoints]);
  return kept;
}

// Apex and the four far corners (image corners at depth `depth`) of a camera's pyramid.
std::vector<Eigen::Vector3d> Frustum(const CameraModel& camera, double depth) {
  std::vector<Eigen::Vector3d> corners = {camera.Center()};
  if (!(camera.K(0, 0) > 0.0) || !(camera.K(1, 1) > 0.0)) return corners;
  const double w = camera.width > 0 ? camera.width : 2.0 * camera.K(0, 2) + 1.0;
  const double h = camera.height > 0 ? camera.height : 2.0 * camera.K(1, 2) + 1.0;
  const Eigen::Matrix3d K_inverse = camera.K.inverse();
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w - 0.5, -0.5),
        Eigen::Vector2d(w - 0.5, h - 0.5), Eigen::Vector2d(-0.5, h - 0.5)}) {
    const Eigen::Vector3d ray = K_inverse * pixel.homogeneous();
    corners.push_back(camera.Center() + camera.R.transpose() * (ray / ray.z() * depth));
  }
  return corners;
}

// The [2 %, 98 %] range of `values` (robust to stray frontier points).
void RobustRange(std::vector<double> values, double* lo, double* hi) {
  if (values.empty()) return;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  *lo = std::min(*lo, values[n * 2 / 100]);
  *hi = std::max(*hi, values[std::min(n - 1, n * 98 / 100)]);
}

// One orthographic view: world point -> (dot(a, X), dot(b, X)).
struct Projection {
  Eigen::Vector3d a, b;
  Eigen::Vector2d operator()(const Eigen::Vector3d& X) const { return {a.dot(X), b.dot(X)}; }
};

void DrawView(const NetworkCalibration& calibration, const std::vector<size_t>& cameras,
              const std::vector<Eigen::Vector3d>& points, const Projection& project, double depth,
              PlotCanvas* canvas, const std::string& title, const std::string& x_label,
              const std::string& y_label) {
  // Ranges: every camera pyramid, and the bulk of the points.
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (size_t i : cameras) {
    for (const Eigen::Vector3d& corner : Frustum(calibration.cameras[i], depth)) {
      const Eigen::Vector2d q = project(corner);
      x_lo = std::min(x_lo, q.x());
      x_hi = std::max(x_hi, q.x());
      y_lo = std::min(y_lo, q.y());
      y_hi = std::max(y_hi, q.y());
    }
    centroid += project(calibration.cameras[i].Center()) / static_cast<double>(cameras.size());
  }
  std::vector<double> xs, ys;
  for (const Eigen::Vector3d& X : points) {
    xs.push_back(project(X).x());
    ys.push_back(project(X).y());
  }
  RobustRange(xs, &x_lo, &x_hi);
  RobustRange(ys, &y_lo, &y_hi);
  if (x_lo > x_hi) x_lo = x_hi = y_lo = y_hi = 0.0;
  const double margin = 0.18 * std::max({x_hi - x_lo, y_hi - y_lo, 1e-9});
  canvas->SetRanges(x_lo - margin, x_hi + margin, y_lo - margin, y_hi + margin);
  canvas->MakeEqualAspect();
  canvas->DrawAxes(x_label, y_label);
  canvas->DrawTitle(title);
  if (cameras.empty() && points.empty()) {
    canvas->DrawMessage("no placed cameras");
    return;
  }

  const cv::Scalar point_colour(150, 150, 150);
  for (const Eigen::Vector3d& X : points) {
    const Eigen::Vector2d q = project(X);
    canvas->Dot(q.x(), q.y(), 0, point_colour);
  }
  for (size_t i : cameras) {
    const std::vector<Eigen::Vector3d> frustum = Frustum(calibration.cameras[i], depth);
    const Eigen::Vector2d apex = project(frustum[0]);
    if (frustum.size() == 5) {
      for (int k = 1; k <= 4; ++k) {
        const Eigen::Vector2d corner = project(frustum[k]);
        const Eigen::Vector2d next = project(frustum[k % 4 + 1]);
        canvas->Line(apex.x(), apex.y(), corner.x(), corner.y(), plot_colour::kBlue);
        // The image's top edge (corners 1-2) drawn thicker shows which way is up.
        canvas->Line(corner.x(), corner.y(), next.x(), next.y(), plot_colour::kBlue,
                     k == 1 ? 2 : 1);
      }
    }
    canvas->Dot(apex.x(), apex.y(), 3, plot_colour::kRed);
  }
  // Labels last, outside the ring (away from the centroid of the cameras), moved up or down
  // when they would cover an earlier one.
  std::vector<cv::Rect> labels;
  for (size_t i : cameras) {
    const Eigen::Vector2d apex = project(calibration.cameras[i].Center());
    Eigen::Vector2d away = apex - centroid;
    away = away.norm() > 1e-12 ? away.normalized() : Eigen::Vector2d(0, 1);
    const TextAnchor anchor = away.x() > 0.3    ? TextAnchor::kLeft
                              : away.x() < -0.3 ? TextAnchor::kRight
                                                : TextAnchor::kCentre;
    const std::string& id = calibration.cameras[i].id;
    const cv::Point2d base(away.x() * 14.0, -away.y() * 14.0);
    cv::Point2d offset = base;
    for (int attempt = 0; attempt < 9; ++attempt) {
      const double shift = 16.0 * ((attempt + 1) / 2) * (attempt % 2 == 1 ? -1.0 : 1.0);
      const cv::Point2d candidate = base + cv::Point2d(0.0, shift);
      const cv::Rect box = TextBox(id, canvas->ToPixel(apex.x(), apex.y()) + candidate,
                                   canvas->font_scale(), anchor, true);
      const bool free = std::none_of(labels.begin(), labels.end(),
                                     [&](const cv::Rect& r) { return !(r & box).empty(); });
      if (free || attempt == 0) offset = candidate;
      if (free) break;
    }
    labels.push_back(TextBox(id, canvas->ToPixel(apex.x(), apex.y()) + offset, canvas->font_scale(),
                             anchor, true));
    canvas->Text(apex.x(), apex.y(), id, plot_colour::kText, anchor, offset);
  }
}

}  // namespace

ViewFrame NetworkViewFrame(const NetworkCalibration& calibration) {
  const std::vector<size_t> cameras = PlacedCameras(calibration);
  ViewFrame frame;
  if (cameras.empty()) return frame;
  Eigen::Vector3d image_up = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_centre = Eigen::Vector3d::Zero();
  for (size_t i : cameras) {
    image_up -= calibration.cameras[i].R.row(1).transpose();
    mean_centre += calibration.cameras[i].Center() / static_cast<double>(cameras.size());
  }
  image_up = image_up.norm() > 1e-9 ? image_up.normalized() : Eigen::Vector3d::UnitZ();
  Eigen::MatrixXd centred(3, cameras.size());
  for (size_t k = 0; k < cameras.size(); ++k)
    centred.col(k) = calibration.cameras[cameras[k]].Center() - mean_centre;
  Eigen::Vector3d up = image_up;
  Eigen::Vector3d spread = Eigen::Vector3d::Zero();
  if (cameras.size() >= 2) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullU);
    const Eigen::Vector3d s = svd.singularValues();
    spread = svd.matrixU().col(0);
    const bool planar = cameras.size() >= 3 && s(1) > 1e-9 * s(0) && s(2) < 0.5 * s(1);
    const Eigen::Vector3d normal = svd.matrixU().col(2);
    if (planar && std::abs(normal.dot(image_up)) > std::cos(std::numbers::pi / 3.0))
      up = normal.dot(image_up) >= 0.0 ? normal : Eigen::Vector3d(-normal);
  }
  // The horizontal axis: the centres' main direction, made perpendicular to up.
  Eigen::Vector3d horizontal = spread - spread.dot(up) * up;
  if (horizontal.norm() < 1e-6) {
    const Eigen::Vector3d x_axis = calibration.cameras[cameras[0]].R.row(0).transpose();
    horizontal = x_axis - x_axis.dot(up) * up;
  }
  frame.up = up;
  frame.horizontal = horizontal.norm() > 1e-6 ? horizontal.normalized() : Perpendicular(up);
  frame.across = up.cross(frame.horizontal);
  return frame;
}

cv::Mat DrawCameraNetwork(const NetworkCalibration& calibration, int width, int height) {
  cv::Mat image = BlankImage(width, height);
  const std::vector<size_t> cameras = PlacedCameras(calibration);
  const std::vector<Eigen::Vector3d> points = PlottedPoints(calibration);
  const ViewFrame frame = NetworkViewFrame(calibration);

  // Pyramids a tenth of the network's size (or of the point cloud's with one camera).
  Eigen::AlignedBox3d box;
  for (size_t i : cameras)
    box.extend(calibration.cameras[i].Center());
  if (cameras.size() < 2) {
    for (const Eigen::Vector3d& X : points)
      box.extend(X);
  }
  const double size = box.isEmpty() ? 0.0 : box.diagonal().norm();
  const double depth = size > 1e-9 ? 0.1 * size : 1.0;

  const int half = width / 2;
  PlotCanvas top(image, cv::Rect(0, 0, half, height));
  PlotCanvas side(image, cv::Rect(half, 0, width - half, height));
  size_t inliers = 0;
  for (const FrontierPoint& p : calibration.points)
    inliers += p.inlier ? 1 : 0;
  const std::string summary =
      points.size() < inliers
          ? fmt::format("{} cameras, {} of {} inlier points", cameras.size(), points.size(),
                        inliers)
          : fmt::format("{} cameras, {} inlier points", cameras.size(), points.size());
  DrawView(calibration, cameras, points, {frame.horizontal, frame.across}, depth, &top,
           "from above (" + summary + ")", "horizontal axis", "across");
  DrawView(calibration, cameras, points, {frame.horizontal, frame.up}, depth, &side,
           "from the side", "horizontal axis", "up");
  return image;
}

}  // namespace silnet::aggregator

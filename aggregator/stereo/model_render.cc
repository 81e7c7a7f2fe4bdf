#include "aggregator/stereo/model_render.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "aggregator/hulls/hull_reprojection.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

const cv::Scalar kBackground(45, 45, 45);
const Eigen::Vector3d kClay(150, 185, 210);  // BGR of a lit surface facing the camera

// Tallest panel of a view picture, pixels.
constexpr int kPanelMaxHeight = 480;

// Sub-pixel precision of the polygon fill (cv::fillConvexPoly's `shift`).
constexpr int kShiftBits = 4;

// A triangle projected into the image, ready to draw.
struct ProjectedTriangle {
  std::array<cv::Point, 3> corners;  // fixed point, kShiftBits fractional bits
  double far_depth = 0;              // its farthest vertex's depth along the optical axis
  double shade = 0;                  // brightness in [0, 1]
};

cv::Point FixedPoint(const Eigen::Vector2d& pixel) {
  const double scale = 1 << kShiftBits;
  return {static_cast<int>(std::lround(pixel.x() * scale)),
          static_cast<int>(std::lround(pixel.y() * scale))};
}

// Lambert brightness of a face with unit normal `n_cam` (camera axes, either orientation)
// seen along the unit ray `towards_face`: a headlight plus a key light above the camera
// (image up is -y in camera axes).
double Shade(const Eigen::Vector3d& n_cam, const Eigen::Vector3d& towards_face) {
  const Eigen::Vector3d to_key_light = Eigen::Vector3d(0.3, -0.7, -1.0).normalized();
  const Eigen::Vector3d facing = n_cam.dot(towards_face) < 0 ? n_cam : Eigen::Vector3d(-n_cam);
  const double headlight = -facing.dot(towards_face);
  const double key = std::max(0.0, facing.dot(to_key_light));
  return std::clamp(0.12 + 0.55 * headlight + 0.33 * key, 0.0, 1.0);
}

}  // namespace

cv::Mat RenderShadedMesh(const TriangleMesh& mesh, const CameraModel& camera) {
  cv::Mat image(camera.height, camera.width, CV_8UC3, kBackground);
  std::vector<Eigen::Vector3d> in_camera(mesh.vertices.size());
  std::vector<std::optional<Eigen::Vector2d>> pixels(mesh.vertices.size());
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    in_camera[v] = camera.R * mesh.vertices[v].cast<double>() + camera.t;
    pixels[v] = camera.Project(mesh.vertices[v].cast<double>());
  }
  std::vector<ProjectedTriangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const auto a = static_cast<size_t>(t[0]), b = static_cast<size_t>(t[1]),
               c = static_cast<size_t>(t[2]);
    if (!pixels[a] || !pixels[b] || !pixels[c]) continue;
    const Eigen::Vector3d normal = (in_camera[b] - in_camera[a]).cross(in_camera[c] - in_camera[a]);
    if (normal.squaredNorm() == 0) continue;
    ProjectedTriangle p;
    p.corners = {FixedPoint(*pixels[a]), FixedPoint(*pixels[b]), FixedPoint(*pixels[c])};
    p.far_depth = std::max({in_camera[a].z(), in_camera[b].z(), in_camera[c].z()});
    const Eigen::Vector3d centre = (in_camera[a] + in_camera[b] + in_camera[c]) / 3;
    p.shade = Shade(normal.normalized(), centre.normalized());
    triangles.push_back(p);
  }
  std::sort(triangles.begin(), triangles.end(),
            [](const ProjectedTriangle& x, const ProjectedTriangle& y) {
              return x.far_depth > y.far_depth;
            });
  for (const ProjectedTriangle& p : triangles) {
    const Eigen::Vector3d bgr = kClay * p.shade;
    cv::fillConvexPoly(image, p.corners.data(), 3, cv::Scalar(bgr.x(), bgr.y(), bgr.z()),
                       cv::LINE_8, kShiftBits);
  }
  return image;
}

cv::Rect SubjectBox(const cv::Mat& mask) {
  cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return {0, 0, mask.cols, mask.rows};
  const int margin = std::max(8, std::max(box.width, box.height) / 8);
  box.x -= margin;
  box.y -= margin;
  box.width += 2 * margin;
  box.height += 2 * margin;
  return box & cv::Rect(0, 0, mask.cols, mask.rows);
}

cv::Mat ViewComparisonPanel(const StereoView& view, const TriangleMesh& mesh, int panel_width) {
  SILNET_CHECK(panel_width > 0 && !view.image.empty() && view.image.size() == view.mask.size());
  const cv::Rect box = SubjectBox(view.mask);
  const std::array<cv::Mat, 3> panels = {
      view.image, RenderShadedMesh(mesh, view.camera),
      ReprojectionOverlay(RenderMeshSilhouette(mesh, view.camera), view.mask)};
  const double scale = std::min({2.0, static_cast<double>(panel_width) / box.width,
                                 static_cast<double>(kPanelMaxHeight) / box.height});
  std::vector<cv::Mat> scaled;
  for (const cv::Mat& panel : panels) {
    cv::Mat resized;
    cv::resize(panel(box), resized, cv::Size(), scale, scale,
               scale < 1 ? cv::INTER_AREA : cv::INTER_NEAREST);
    scaled.push_back(resized);
  }
  cv::Mat row;
  cv::hconcat(scaled, row);
  return row;
}

}  // namespace silnet::aggregator

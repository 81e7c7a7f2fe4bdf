#include "aggregator/hulls/hull_reprojection.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// Sets every pixel whose centre lies in the closed triangle (either winding).
void FillTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                  cv::Mat* image) {
  ForEachPixelInTriangle(a, b, c, image->cols, image->rows,
                         [image](int x, int y) { image->at<uint8_t>(y, x) = 255; });
}

// The silhouette pixels whose centre lies more than kFarFromOutlinePx from the outline, which
// runs half a pixel outside the boundary pixel centres: no background pixel centre within
// kFarFromOutlinePx + 0.5 (an erosion by that disc; outside the image counts as silhouette).
cv::Mat FarFromOutline(const cv::Mat& inside) {
  const double radius = kFarFromOutlinePx + 0.5;
  const int r = static_cast<int>(std::floor(radius));
  cv::Mat disc = cv::Mat::zeros(2 * r + 1, 2 * r + 1, CV_8UC1);
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      if (dx * dx + dy * dy <= radius * radius) disc.at<uint8_t>(dy + r, dx + r) = 1;
    }
  }
  cv::Mat far;
  cv::erode(inside, far, disc, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar::all(255));
  return far;
}

}  // namespace

VertexPixels ProjectVertices(const TriangleMesh& mesh, const CameraModel& camera) {
  VertexPixels out;
  out.pixels.resize(mesh.vertices.size());
  out.in_front.assign(mesh.vertices.size(), 0);
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto p = camera.Project(mesh.vertices[v].cast<double>());
    if (!p) continue;
    out.pixels[v] = *p;
    out.in_front[v] = 1;
  }
  return out;
}

cv::Mat RenderMeshSilhouette(const TriangleMesh& mesh, const CameraModel& camera) {
  return RenderMeshSilhouette(mesh, ProjectVertices(mesh, camera), camera.width, camera.height);
}

cv::Mat RenderMeshSilhouette(const TriangleMesh& mesh, const VertexPixels& projected, int width,
                             int height) {
  SILNET_CHECK(projected.pixels.size() == mesh.vertices.size() &&
               projected.in_front.size() == mesh.vertices.size());
  cv::Mat image = cv::Mat::zeros(height, width, CV_8UC1);
  const auto& [pixels, in_front] = projected;
  for (const auto& t : mesh.triangles) {
    const auto a = static_cast<size_t>(t[0]), b = static_cast<size_t>(t[1]);
    const auto c = static_cast<size_t>(t[2]);
    if (!in_front[a] || !in_front[b] || !in_front[c]) continue;
    FillTriangle(pixels[a], pixels[b], pixels[c], &image);
  }
  return image;
}

ViewReprojection CompareWithSilhouette(const cv::Mat& rendered, const cv::Mat& silhouette) {
  SILNET_CHECK(rendered.type() == CV_8UC1 && silhouette.type() == CV_8UC1);
  SILNET_CHECK(rendered.size() == silhouette.size());
  ViewReprojection result;
  const cv::Mat covered = rendered != 0, inside = silhouette != 0;
  result.silhouette_pixels = static_cast<size_t>(cv::countNonZero(inside));
  result.missed_pixels = static_cast<size_t>(cv::countNonZero(inside & ~covered));
  result.spurious_pixels = static_cast<size_t>(cv::countNonZero(covered & ~inside));
  if (result.silhouette_pixels > 0) {
    const auto n = static_cast<double>(result.silhouette_pixels);
    result.missed_fraction = static_cast<double>(result.missed_pixels) / n;
    result.spurious_fraction = static_cast<double>(result.spurious_pixels) / n;
  }
  if (result.missed_pixels > 0) {
    result.missed_far_pixels =
        static_cast<size_t>(cv::countNonZero(FarFromOutline(inside) & ~covered));
    result.missed_far_fraction = static_cast<double>(result.missed_far_pixels) /
                                 static_cast<double>(result.silhouette_pixels);
  }
  return result;
}

std::vector<ViewReprojection> MeasureHullReprojection(const TriangleMesh& mesh,
                                                      const std::vector<CameraModel>& cameras,
                                                      const std::vector<cv::Mat>& silhouettes) {
  SILNET_CHECK(cameras.size() == silhouettes.size());
  std::vector<ViewReprojection> views;
  for (size_t c = 0; c < cameras.size(); ++c) {
    views.push_back(CompareWithSilhouette(RenderMeshSilhouette(mesh, cameras[c]), silhouettes[c]));
    views.back().camera_id = cameras[c].id;
  }
  return views;
}

cv::Mat ReprojectionOverlay(const cv::Mat& rendered, const cv::Mat& silhouette) {
  SILNET_CHECK(rendered.type() == CV_8UC1 && silhouette.type() == CV_8UC1);
  SILNET_CHECK(rendered.size() == silhouette.size());
  cv::Mat overlay = cv::Mat::zeros(rendered.size(), CV_8UC3);
  const cv::Mat covered = rendered != 0, inside = silhouette != 0;
  overlay.setTo(cv::Scalar(255, 255, 255), covered & inside);
  overlay.setTo(cv::Scalar(0, 0, 255), inside & ~covered);  // missed: red (BGR)
  overlay.setTo(cv::Scalar(255, 0, 0), covered & ~inside);  // spurious: blue
  return overlay;
}

void WriteReprojectionOverlay(const std::string& path, const cv::Mat& rendered,
                              const cv::Mat& silhouette) {
  bool written = false;
  try {
    written = cv::imwrite(path, ReprojectionOverlay(rendered, silhouette));
  } catch (const cv::Exception& e) {
    throw InputError("cannot write " + path + ": " + e.what());
  }
  if (!written) throw InputError("cannot write " + path);
}

}  // namespace silnet::aggregator

#pragma once
// How well a hull explains its silhouettes: the hull's surface mesh is rendered into each
// view and compared with the silhouette pixel by pixel (thesis 4.2, the consistency check of
// a visual hull). A rendered pixel is covered iff its centre lies inside (or on the edge
// of) a projected triangle; triangles are projected through the camera's distortion at
// their vertices and drawn with straight edges.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "aggregator/hulls/triangle_mesh.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The comparison of one view.
struct ViewReprojection {
  std::string camera_id;
  size_t silhouette_pixels = 0;  // non-zero pixels of the silhouette
  size_t missed_pixels = 0;      // silhouette pixels the hull does not cover
  size_t spurious_pixels = 0;    // covered pixels outside the silhouette
  double missed_fraction = 0;    // missed / silhouette pixels (0 if the silhouette is empty)
  double spurious_fraction = 0;  // spurious / silhouette pixels (0 if the silhouette is empty)
  // Missed pixels farther than kFarFromOutlinePx from the silhouette's outline (their centre
  // more than 2.5 px from every background pixel centre): the misses a calibration that
  // disagrees with the masks by a pixel or two does not explain.
  size_t missed_far_pixels = 0;
  double missed_far_fraction = 0;  // missed_far / silhouette pixels
};

// Distance from the silhouette outline beyond which a missed pixel counts as far (pixels).
inline constexpr double kFarFromOutlinePx = 2.0;

// Twice the signed area of (a, b, p); >= 0 when p is left of a -> b (image axes).
inline double EdgeFunction(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                           const Eigen::Vector2d& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

// Calls visit(x, y) for every pixel of a `width` x `height` image whose centre lies in the
// closed triangle (a, b, c) (either winding; none for a degenerate one): the pixels
// RenderMeshSilhouette covers with that triangle.
template <typename Visit>
void ForEachPixelInTriangle(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                            const Eigen::Vector2d& c, int width, int height, Visit&& visit) {
  const double area = EdgeFunction(a, b, c);
  if (area == 0.0) return;
  const double sign = area > 0 ? 1.0 : -1.0;
  const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
  const int x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
  const int y1 =
      std::min(height - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const Eigen::Vector2d p(x, y);
      if (sign * EdgeFunction(a, b, p) >= 0 && sign * EdgeFunction(b, c, p) >= 0 &&
          sign * EdgeFunction(c, a, p) >= 0) {
        visit(x, y);
      }
    }
  }
}

// A mesh's vertices in one camera's image: each vertex's pixel, and whether it lies in front
// of the camera (its pixel is meaningless otherwise).
struct VertexPixels {
  std::vector<Eigen::Vector2d> pixels;
  std::vector<uint8_t> in_front;
};
VertexPixels ProjectVertices(const TriangleMesh& mesh, const CameraModel& camera);

// CV_8UC1 image of the camera's size, 255 where the mesh covers the pixel centre.
// Triangles with a vertex behind the camera are skipped.
cv::Mat RenderMeshSilhouette(const TriangleMesh& mesh, const CameraModel& camera);
// The same from the vertices already projected into that camera (`width` x `height`).
cv::Mat RenderMeshSilhouette(const TriangleMesh& mesh, const VertexPixels& projected, int width,
                             int height);

// Compares a rendered coverage image with a silhouette (both CV_8UC1, same size).
ViewReprojection CompareWithSilhouette(const cv::Mat& rendered, const cv::Mat& silhouette);

// Renders `mesh` into every camera and compares it with that camera's silhouette.
std::vector<ViewReprojection> MeasureHullReprojection(const TriangleMesh& mesh,
                                                      const std::vector<CameraModel>& cameras,
                                                      const std::vector<cv::Mat>& silhouettes);

// BGR picture of the comparison: silhouette pixels the hull covers in white, missed
// silhouette pixels in red, spurious covered pixels in blue, background black.
cv::Mat ReprojectionOverlay(const cv::Mat& rendered, const cv::Mat& silhouette);

// Writes ReprojectionOverlay as an image file (format from the extension, e.g. ".png").
// Throws InputError if it cannot be written.
void WriteReprojectionOverlay(const std::string& path, const cv::Mat& rendered,
                              const cv::Mat& silhouette);

}  // namespace silnet::aggregator

#include "shared/silhouette/silhouette_hull.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <opencv2/core.hpp>

#include "shared/silhouette/lattice_boundary.h"
#include "shared/silhouette/melkman_hull.h"
#include "shared/util/check.h"

namespace silnet {
namespace {

// First and last nonzero byte of a row; false if the row is all zero. Scans eight bytes
// at a time where possible.
bool RowExtent(const uint8_t* row, int width, int* first, int* last) {
  int x = 0;
  while (x + 8 <= width) {
    uint64_t word;
    std::memcpy(&word, row + x, 8);
    if (word != 0) break;
    x += 8;
  }
  while (x < width && row[x] == 0)
    ++x;
  if (x == width) return false;
  *first = x;
  int y = width - 1;
  while (y - 8 >= x) {
    uint64_t word;
    std::memcpy(&word, row + y - 7, 8);
    if (word != 0) break;
    y -= 8;
  }
  while (row[y] == 0)
    --y;
  *last = y;
  return true;
}

// True if the segment a-b lies on the line x = low, y = low, x = high_x or y = high_y.
bool OnBorderLine(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double low, double high_x,
                  double high_y) {
  return (a.x() == low && b.x() == low) || (a.y() == low && b.y() == low) ||
         (a.x() == high_x && b.x() == high_x) || (a.y() == high_y && b.y() == high_y);
}

// The hull with its edges on the image border (x = -0.5, y = -0.5, x = width - 0.5 or
// y = height - 0.5) marked clipped.
SilhouetteHull WithClippedEdges(std::vector<Eigen::Vector2d> hull, int width, int height) {
  std::vector<bool> clipped(hull.size(), false);
  for (size_t i = 0; i < hull.size(); ++i) {
    clipped[i] =
        OnBorderLine(hull[i], hull[(i + 1) % hull.size()], -0.5, width - 0.5, height - 0.5);
  }
  return SilhouetteHull(std::move(hull), std::move(clipped));
}

// The hull of the pixel squares around one or two pixel centres (a dot or a straight run of
// pixels), whose hull of centres is degenerate.
SilhouetteHull PixelSquaresHull(const std::vector<Eigen::Vector2d>& centres, int width,
                                int height) {
  std::vector<Eigen::Vector2d> corners;
  for (const Eigen::Vector2d& c : centres) {
    for (const Eigen::Vector2d& offset : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(-0.5, 0.5),
                                          Eigen::Vector2d(0.5, 0.5), Eigen::Vector2d(0.5, -0.5)}) {
      corners.push_back(c + offset);
    }
  }
  std::sort(corners.begin(), corners.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.y() < b.y() || (a.y() == b.y() && a.x() < b.x());
  });
  return WithClippedEdges(SortedPointsHull(corners), width, height);
}

}  // namespace

double DirectionAngle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  double angle = std::atan2(b.y() - a.y(), b.x() - a.x());
  if (angle < 0.0) angle += 2.0 * std::numbers::pi;
  return angle;
}

SilhouetteHull::SilhouetteHull(std::vector<Eigen::Vector2d> vertices, std::vector<bool> clipped)
    : vertices_(std::move(vertices)), clipped_(std::move(clipped)) {
  SILNET_CHECK(clipped_.size() == vertices_.size());
  angles_.resize(vertices_.size());
  for (size_t i = 0; i < vertices_.size(); ++i) {
    angles_[i] = DirectionAngle(vertices_[i], vertices_[(i + 1) % vertices_.size()]);
  }
}

bool SilhouetteHull::any_clipped() const {
  for (bool c : clipped_) {
    if (c) return true;
  }
  return false;
}

bool SilhouetteHull::vertex_on_clipped_edge(int i) const {
  const int n = size();
  return clipped_[static_cast<size_t>(i)] || clipped_[static_cast<size_t>((i + n - 1) % n)];
}

double SilhouetteHull::Area() const {
  double twice = 0.0;
  for (size_t i = 0; i < vertices_.size(); ++i) {
    const Eigen::Vector2d& a = vertices_[i];
    const Eigen::Vector2d& b = vertices_[(i + 1) % vertices_.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * twice;
}

bool SilhouetteHull::Contains(const Eigen::Vector2d& point) const {
  if (vertices_.size() < 3) return false;
  for (size_t i = 0; i < vertices_.size(); ++i) {
    if (Orientation(vertices_[i], vertices_[(i + 1) % vertices_.size()], point) < -1e-9) {
      return false;
    }
  }
  return true;
}

SilhouetteHull ComputeSilhouetteHull(const cv::Mat& mask, MaskSummary* summary) {
  SILNET_CHECK_MSG(mask.type() == CV_8UC1, "silhouette masks are CV_8UC1, got " << mask.type());
  const int width = mask.cols, height = mask.rows;
  // Row extents, top to bottom: the left boundary goes down, the right boundary comes up.
  std::vector<Eigen::Vector2d> extents;  // sorted by (y, x)
  int top = -1, bottom = -1;
  bool touches = false;
  for (int y = 0; y < height; ++y) {
    int first = 0, last = 0;
    if (!RowExtent(mask.ptr<uint8_t>(y), width, &first, &last)) continue;
    if (top < 0) top = y;
    bottom = y;
    touches = touches || first == 0 || last == width - 1;
    extents.emplace_back(first, y);
    if (last != first) extents.emplace_back(last, y);
  }
  if (summary != nullptr) {
    summary->foreground_pixels = top < 0 ? 0 : cv::countNonZero(mask);
    summary->touches_border = touches || top == 0 || bottom == height - 1;
  }
  if (top < 0) return {};
  const std::vector<Eigen::Vector2d> centres = SortedPointsHull(extents);
  if (centres.size() < 3) return PixelSquaresHull(centres, width, height);
  // The boundary model, on the wire's grid; rounding may leave repeated or collinear
  // vertices, which the simple polygon's hull drops.
  std::vector<Eigen::Vector2d> boundary = LatticeBoundaryPolygon(centres, width, height);
  for (Eigen::Vector2d& v : boundary) {
    v = (v / kHullVertexStep).array().round().matrix() * kHullVertexStep;
  }
  std::vector<Eigen::Vector2d> hull = MelkmanHull(boundary);
  if (hull.size() < 3) return PixelSquaresHull(centres, width, height);
  return WithClippedEdges(std::move(hull), width, height);
}

}  // namespace silnet

#include "shared/silhouette/silhouette_hull.h"

#include <cmath>
#include <cstring>
#include <numbers>
#include <opencv2/core.hpp>

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
  std::vector<Eigen::Vector2d> left, right;
  int top = -1, bottom = -1, top_first = 0, top_last = 0, bottom_first = 0, bottom_last = 0;
  bool touches = false;
  for (int y = 0; y < height; ++y) {
    int first = 0, last = 0;
    if (!RowExtent(mask.ptr<uint8_t>(y), width, &first, &last)) continue;
    if (top < 0) {
      top = y;
      top_first = first;
      top_last = last;
    }
    bottom = y;
    bottom_first = first;
    bottom_last = last;
    touches = touches || first == 0 || last == width - 1;
    left.emplace_back(first - 0.5, y);
    right.emplace_back(last + 0.5, y);
  }
  if (summary != nullptr) {
    summary->foreground_pixels = top < 0 ? 0 : cv::countNonZero(mask);
    summary->touches_border = touches || top == 0 || bottom == height - 1;
  }
  if (top < 0) return {};
  // The simple polygon: top edge, down the left, bottom edge, up the right.
  std::vector<Eigen::Vector2d> polygon;
  polygon.reserve(left.size() + right.size() + 4);
  polygon.emplace_back(top_first, top - 0.5);
  polygon.insert(polygon.end(), left.begin(), left.end());
  polygon.emplace_back(bottom_first, bottom + 0.5);
  polygon.emplace_back(bottom_last, bottom + 0.5);
  polygon.insert(polygon.end(), right.rbegin(), right.rend());
  polygon.emplace_back(top_last, top - 0.5);
  std::vector<Eigen::Vector2d> hull = MelkmanHull(polygon);
  // Clipped edges lie on a border line of the image.
  auto on_border = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() == -0.5 && b.x() == -0.5) || (a.y() == -0.5 && b.y() == -0.5) ||
           (a.x() == width - 0.5 && b.x() == width - 0.5) ||
           (a.y() == height - 0.5 && b.y() == height - 0.5);
  };
  std::vector<bool> clipped(hull.size(), false);
  for (size_t i = 0; i < hull.size(); ++i) {
    clipped[i] = on_border(hull[i], hull[(i + 1) % hull.size()]);
  }
  return SilhouetteHull(std::move(hull), std::move(clipped));
}

}  // namespace silnet

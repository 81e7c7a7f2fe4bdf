#include "aggregator/pairwise/fundamental_distance.h"

#include <cmath>
#include <vector>

#include "shared/geometry/epipolar.h"

namespace silnet::aggregator {
namespace {

// Points where a line crosses the image (up to the two border crossings and their middle).
std::vector<Eigen::Vector2d> PointsOnLineInImage(const Eigen::Vector3d& line, int width,
                                                 int height) {
  std::vector<Eigen::Vector2d> crossings;
  const double w = width - 1.0, h = height - 1.0;
  auto add = [&](double x, double y) {
    if (x >= -1e-9 && x <= w + 1e-9 && y >= -1e-9 && y <= h + 1e-9) crossings.emplace_back(x, y);
  };
  if (std::abs(line.y()) > 1e-12) {
    add(0.0, -line.z() / line.y());
    add(w, -(line.z() + line.x() * w) / line.y());
  }
  if (std::abs(line.x()) > 1e-12) {
    add(-line.z() / line.x(), 0.0);
    add(-(line.z() + line.y() * h) / line.x(), h);
  }
  if (crossings.size() < 2) return crossings;
  const Eigen::Vector2d a = crossings[0], b = crossings.back();
  return {a, 0.5 * (a + b), b};
}

// One direction: points of image `from`, epipolar lines under `a` in the other image,
// points on them, distances to the lines under `b` (and back).
void Accumulate(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b, int width, int height,
                double* sum, int* count) {
  for (int gy = 1; gy <= 5; ++gy) {
    for (int gx = 1; gx <= 5; ++gx) {
      const Eigen::Vector2d x(width * gx / 6.0, height * gy / 6.0);
      for (const Eigen::Vector2d& y : PointsOnLineInImage(a * x.homogeneous(), width, height)) {
        *sum += PointLineDistance(b * x.homogeneous(), y) +
                PointLineDistance(b.transpose() * y.homogeneous(), x);
        *count += 2;
      }
    }
  }
}

}  // namespace

double FundamentalDistance(const Eigen::Matrix3d& f1, const Eigen::Matrix3d& f2, int width,
                           int height) {
  double sum = 0.0;
  int count = 0;
  Accumulate(f1, f2, width, height, &sum, &count);
  Accumulate(f2, f1, width, height, &sum, &count);
  Accumulate(f1.transpose(), f2.transpose(), width, height, &sum, &count);
  Accumulate(f2.transpose(), f1.transpose(), width, height, &sum, &count);
  return count == 0 ? 0.0 : sum / count;
}

}  // namespace silnet::aggregator

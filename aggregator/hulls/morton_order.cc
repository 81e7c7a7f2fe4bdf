#include "aggregator/hulls/morton_order.h"

#include <algorithm>
#include <utility>

namespace silnet::aggregator {
namespace {

// Cells per axis - 1 (21 bits).
constexpr double kLastCell = double{(1 << 21) - 1};

// Spreads the low 21 bits of `v` to every third bit.
uint64_t SpreadBits(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

Eigen::AlignedBox3d BoundingBox(const std::vector<Eigen::Vector3d>& points) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : points)
    box.extend(p);
  return box;
}

}  // namespace

MortonCurve::MortonCurve(const Eigen::AlignedBox3d& box) {
  if (box.isEmpty()) return;
  lo_ = box.min();
  scale_ = (kLastCell / box.sizes().array().max(1e-12)).matrix();
}

MortonCurve::MortonCurve(const std::vector<Eigen::Vector3d>& points)
    : MortonCurve(BoundingBox(points)) {}

uint64_t MortonCurve::Code(const Eigen::Vector3d& p) const {
  uint64_t code = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double cell = (p[axis] - lo_[axis]) * scale_[axis];
    code |= SpreadBits(static_cast<uint64_t>(cell > 0 ? std::min(cell, kLastCell) : 0.0)) << axis;
  }
  return code;
}

std::vector<uint32_t> MortonCurve::Order(const std::vector<Eigen::Vector3d>& points) const {
  std::vector<std::pair<uint64_t, uint32_t>> keyed(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    keyed[i] = {Code(points[i]), static_cast<uint32_t>(i)};
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> order(points.size());
  for (size_t i = 0; i < keyed.size(); ++i)
    order[i] = keyed[i].second;
  return order;
}

}  // namespace silnet::aggregator

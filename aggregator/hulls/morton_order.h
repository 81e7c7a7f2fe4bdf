#pragma once
// Positions on the Morton (Z-order) curve, for laying out points so that points near in space
// sit near in memory: the k-d tree of nearest_point.h, the node order of the tetrahedral
// graph cut.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace silnet::aggregator {

// The Morton curve over a box, 21 bits per axis, each axis scaled to the box's extent along it.
class MortonCurve {
 public:
  // The curve over `box` (an empty or flat box is fine: its flat axes all map to cell 0).
  explicit MortonCurve(const Eigen::AlignedBox3d& box);
  // The curve over the bounding box of `points`.
  explicit MortonCurve(const std::vector<Eigen::Vector3d>& points);

  // The position of `p` on the curve, p clamped to the box (NaN coordinates to its low side):
  // points close in space mostly get close codes.
  uint64_t Code(const Eigen::Vector3d& p) const;

  // The indices of `points` in curve order (ties by index: deterministic).
  std::vector<uint32_t> Order(const std::vector<Eigen::Vector3d>& points) const;

 private:
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d scale_ = Eigen::Vector3d::Zero();
};

}  // namespace silnet::aggregator

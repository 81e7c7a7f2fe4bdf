#pragma once
// The view graph of a camera network (thesis 3.2): cameras as nodes, trusted pairwise
// epipolar geometries as links, each with its frontier-point correspondences and its inlier
// spread score (3.2.3), by which links are ranked.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "aggregator/pairwise/epipolar_tangent_ransac.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// A frontier-point correspondence of a camera pair, in raw pixels of each view.
struct Correspondence {
  Eigen::Vector2d x_i = Eigen::Vector2d::Zero();
  Eigen::Vector2d x_j = Eigen::Vector2d::Zero();
  uint64_t frame_i = 0;
};

// One link: cameras i < j, x_j^T F x_i = 0 (pixels), the correspondences and the score.
struct ViewLink {
  size_t i = 0;
  size_t j = 0;
  Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  double spread = 0.0;
  std::vector<Correspondence> matches;
};

// The links between `cameras` cameras.
class ViewGraph {
 public:
  explicit ViewGraph(size_t cameras) : cameras_(cameras) {}

  // Adds a link; i != j, both below the camera count (CheckError otherwise). A link between
  // cameras already linked replaces the old one.
  void Add(ViewLink link);

  size_t cameras() const { return cameras_; }
  const std::vector<ViewLink>& links() const { return links_; }
  // The link between a and b in either order, or null.
  const ViewLink* Find(size_t a, size_t b) const;
  // F mapping points of a to lines of b (x_b^T F x_a = 0); the link must exist.
  Eigen::Matrix3d FundamentalFromTo(size_t a, size_t b) const;
  // Spread score of the link a-b, or -1 without a link.
  double Spread(size_t a, size_t b) const;
  // Cameras linked to `camera`.
  std::vector<size_t> Neighbours(size_t camera) const;

 private:
  size_t cameras_;
  std::vector<ViewLink> links_;
};

// Index of the camera named `id` in `cameras`, or cameras.size() if there is none.
size_t CameraIndex(const std::vector<CameraModel>& cameras, const std::string& id);

// The view graph of the ok pairs among `camera_ids` (pairs naming unknown cameras are
// ignored); correspondences at each pair's estimated offset.
ViewGraph BuildViewGraph(const std::vector<std::string>& camera_ids,
                         const std::vector<PairwiseResult>& pairs);

}  // namespace silnet::aggregator

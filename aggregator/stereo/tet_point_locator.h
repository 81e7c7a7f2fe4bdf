#pragma once
// Point location in a tetrahedral mesh: a uniform grid of buckets over the mesh's box, each
// listing the tetrahedra whose bounding boxes overlap it, and an exact barycentric test among
// them. Used to walk viewing rays through the adaptive mesh (thesis 7.3.3, 7.4.2) by sampling
// them finer than its smallest cells.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "aggregator/stereo/bcc_lattice.h"

namespace silnet::aggregator {

// Finds the tetrahedron holding a point.
class TetPointLocator {
 public:
  // Indexes `mesh` (kept by reference: it must outlive the locator) with buckets of about
  // `bucket_size` metres (> 0) per side.
  TetPointLocator(const TetMesh& mesh, double bucket_size);

  // A tetrahedron holding p (on a shared face or edge: one of them), or -1 outside the mesh.
  int32_t Locate(const Eigen::Vector3d& p) const;

 private:
  const TetMesh& mesh_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double bucket_ = 1.0;
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<uint32_t> first_;  // per bucket, into ids_; one more entry at the end
  std::vector<int32_t> ids_;
};

}  // namespace silnet::aggregator

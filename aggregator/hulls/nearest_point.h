#pragma once
// Exact nearest points of a fixed 3D point set, by a k-d tree (nanoflann's single
// deterministic tree, exact search: the same answers every run and on any thread count). For
// surface distances: hulls against their truth (mesh_measure.h), the Middlebury measures of
// stereo models (stereo/model_evaluation.h) and the checks of vote lattices.

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

namespace silnet::aggregator {

// A k-d tree over a point set (metres). A query of many points is answered on `threads`
// threads (0 = all cores), the same answers as on one.
class NearestPoint {
 public:
  // Indexes `points` (copied, stored as float). An empty set answers every query with
  // infinity and index -1.
  explicit NearestPoint(const std::vector<Eigen::Vector3d>& points, int threads = 0);
  ~NearestPoint();
  NearestPoint(const NearestPoint&) = delete;
  NearestPoint& operator=(const NearestPoint&) = delete;

  // Distance from each query to its nearest point, metres.
  std::vector<double> Distances(const std::vector<Eigen::Vector3d>& queries) const;

  // The `k` nearest points of each query, nearest first: `indices` and `distances` (metres)
  // get queries.size() * k entries, query-major. With fewer than k points the missing
  // entries are index -1 at infinite distance.
  void KNearest(const std::vector<Eigen::Vector3d>& queries, int k, std::vector<int>* indices,
                std::vector<double>* distances) const;

  // Number of points indexed.
  size_t size() const { return size_; }

 private:
  struct Index;
  std::unique_ptr<Index> index_;
  size_t size_ = 0;
  int threads_ = 0;
};

}  // namespace silnet::aggregator

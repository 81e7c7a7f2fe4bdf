#include "aggregator/hulls/nearest_point.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nanoflann.hpp>

#include "aggregator/hulls/morton_order.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Queries answered per task: enough to make a task's overhead negligible.
constexpr size_t kQueriesPerTask = 8192;

// The indexed points as nanoflann reads them.
struct PointCloud {
  std::vector<Eigen::Vector3f> points;

  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t index, size_t axis) const {
    return points[index][static_cast<Eigen::Index>(axis)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;  // nanoflann computes the bounding box itself
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointCloud>,
                                                   PointCloud, 3, uint32_t>;

}  // namespace

// The points are stored in Morton order, and queries answered in that order too, so that
// consecutive searches walk the same parts of the tree and of memory.
struct NearestPoint::Index {
  MortonCurve curve;
  PointCloud cloud;                // the points in curve order
  std::vector<uint32_t> original;  // cloud index -> index in the points given
  std::unique_ptr<KdTree> tree;

  explicit Index(const std::vector<Eigen::Vector3d>& points) : curve(points) {}
};

NearestPoint::NearestPoint(const std::vector<Eigen::Vector3d>& points, int threads)
    : index_(std::make_unique<Index>(points)), size_(points.size()), threads_(threads) {
  SILNET_CHECK(threads >= 0);
  SILNET_CHECK(points.size() < std::numeric_limits<uint32_t>::max());
  if (points.empty()) return;
  index_->original = index_->curve.Order(points);
  index_->cloud.points.reserve(points.size());
  for (uint32_t i : index_->original)
    index_->cloud.points.push_back(points[i].cast<float>());
  // Built once, deterministically (no randomised splits): the same answers every run.
  index_->tree =
      std::make_unique<KdTree>(3, index_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
}

NearestPoint::~NearestPoint() = default;

std::vector<double> NearestPoint::Distances(const std::vector<Eigen::Vector3d>& queries) const {
  std::vector<int> indices;
  std::vector<double> distances;
  KNearest(queries, 1, &indices, &distances);
  return distances;
}

void NearestPoint::KNearest(const std::vector<Eigen::Vector3d>& queries, int k,
                            std::vector<int>* indices, std::vector<double>* distances) const {
  SILNET_CHECK(k >= 1);
  const size_t n = queries.size(), kk = static_cast<size_t>(k);
  indices->assign(n * kk, -1);
  distances->assign(n * kk, std::numeric_limits<double>::infinity());
  if (queries.empty() || size_ == 0) return;
  const std::vector<uint32_t> order = index_->curve.Order(queries);
  // Searching reads the tree only (each query's result set is its own), so tasks share it.
  const size_t tasks = (n + kQueriesPerTask - 1) / kQueriesPerTask;
  ParallelFor(tasks, threads_, [&](size_t task) {
    std::vector<uint32_t> found(kk);
    std::vector<float> squared(kk);
    const size_t last = std::min(n, (task + 1) * kQueriesPerTask);
    for (size_t rank = task * kQueriesPerTask; rank < last; ++rank) {
      const size_t q = order[rank];
      const Eigen::Vector3f query = queries[q].cast<float>();
      nanoflann::KNNResultSet<float, uint32_t> result(kk);
      result.init(found.data(), squared.data());
      index_->tree->findNeighbors(result, query.data(), nanoflann::SearchParams());
      for (size_t j = 0; j < result.size(); ++j) {
        (*indices)[q * kk + j] = static_cast<int>(index_->original[found[j]]);
        (*distances)[q * kk + j] = std::sqrt(static_cast<double>(squared[j]));
      }
    }
  });
}

}  // namespace silnet::aggregator

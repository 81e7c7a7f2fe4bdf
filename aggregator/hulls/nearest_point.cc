#include "aggregator/hulls/nearest_point.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nanoflann.hpp>
#include <utility>

#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// Queries answered per task: enough to make a task's overhead negligible.
constexpr size_t kQueriesPerTask = 8192;

// Bits per axis of the Morton codes that order points along a space-filling curve.
constexpr int kMortonBits = 21;

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

// A point's position on the Morton curve over the box [lo, lo + 1/scale]^3 (points outside
// clamped to it): points close in space mostly get close codes.
struct MortonCurve {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();
  double scale = 0;

  explicit MortonCurve(const std::vector<Eigen::Vector3d>& points) {
    if (points.empty()) return;
    Eigen::Vector3d hi = points.front();
    lo = hi;
    for (const Eigen::Vector3d& p : points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const double extent = (hi - lo).maxCoeff();
    scale = extent > 0 ? static_cast<double>((1 << kMortonBits) - 1) / extent : 0.0;
  }

  uint64_t Code(const Eigen::Vector3d& p) const {
    constexpr double kLastCell = static_cast<double>((1 << kMortonBits) - 1);
    uint64_t code = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const double cell = (p[axis] - lo[axis]) * scale;  // NaN and below the box: cell 0
      code |= SpreadBits(static_cast<uint64_t>(cell > 0 ? std::min(cell, kLastCell) : 0.0)) << axis;
    }
    return code;
  }

  // The indices of `points` in curve order (ties by index: deterministic).
  std::vector<uint32_t> Order(const std::vector<Eigen::Vector3d>& points) const {
    std::vector<std::pair<uint64_t, uint32_t>> keyed(points.size());
    for (size_t i = 0; i < points.size(); ++i)
      keyed[i] = {Code(points[i]), static_cast<uint32_t>(i)};
    std::sort(keyed.begin(), keyed.end());
    std::vector<uint32_t> order(points.size());
    for (size_t i = 0; i < keyed.size(); ++i)
      order[i] = keyed[i].second;
    return order;
  }
};

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

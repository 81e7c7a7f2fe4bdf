#include "aggregator/stereo/nearest_point.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/flann.hpp>

#include "shared/util/check.h"

namespace silnet::aggregator {

struct NearestPoint::Index {
  cv::Mat points;
  std::unique_ptr<cv::flann::Index> tree;
};

namespace {

cv::Mat ToMat(const std::vector<Eigen::Vector3d>& points) {
  cv::Mat mat(static_cast<int>(points.size()), 3, CV_32F);
  for (size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < 3; ++a)
      mat.at<float>(static_cast<int>(i), a) = static_cast<float>(points[i][a]);
  return mat;
}

}  // namespace

NearestPoint::NearestPoint(const std::vector<Eigen::Vector3d>& points)
    : index_(std::make_unique<Index>()), size_(points.size()) {
  if (points.empty()) return;
  index_->points = ToMat(points);
  // One deterministic k-d tree (no randomised split dimensions): the same answers every run.
  cv::flann::IndexParams params;
  params.setAlgorithm(cvflann::FLANN_INDEX_KDTREE_SINGLE);
  params.setInt("leaf_max_size", 10);
  params.setBool("reorder", true);
  params.setInt("dim", -1);
  index_->tree = std::make_unique<cv::flann::Index>(index_->points, params);
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
  const int found = static_cast<int>(std::min(kk, size_));
  cv::Mat nearest, squared;
  index_->tree->knnSearch(ToMat(queries), nearest, squared, found, cv::flann::SearchParams(-1));
  for (size_t i = 0; i < n; ++i) {
    for (int j = 0; j < found; ++j) {
      const int row = static_cast<int>(i);
      (*indices)[i * kk + static_cast<size_t>(j)] = nearest.at<int>(row, j);
      (*distances)[i * kk + static_cast<size_t>(j)] =
          std::sqrt(static_cast<double>(squared.at<float>(row, j)));
    }
  }
}

}  // namespace silnet::aggregator

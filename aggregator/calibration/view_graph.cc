#include "aggregator/calibration/view_graph.h"

#include <algorithm>

#include "shared/util/check.h"

namespace silnet::aggregator {

void ViewGraph::Add(ViewLink link) {
  SILNET_CHECK(link.i != link.j && link.i < cameras_ && link.j < cameras_);
  if (link.i > link.j) {
    std::swap(link.i, link.j);
    link.F.transposeInPlace();
    for (Correspondence& c : link.matches)
      std::swap(c.x_i, c.x_j);
  }
  for (ViewLink& existing : links_) {
    if (existing.i == link.i && existing.j == link.j) {
      existing = std::move(link);
      return;
    }
  }
  links_.push_back(std::move(link));
}

const ViewLink* ViewGraph::Find(size_t a, size_t b) const {
  const size_t i = std::min(a, b), j = std::max(a, b);
  for (const ViewLink& link : links_) {
    if (link.i == i && link.j == j) return &link;
  }
  return nullptr;
}

Eigen::Matrix3d ViewGraph::FundamentalFromTo(size_t a, size_t b) const {
  const ViewLink* link = Find(a, b);
  SILNET_CHECK(link != nullptr);
  return link->i == a ? link->F : Eigen::Matrix3d(link->F.transpose());
}

double ViewGraph::Spread(size_t a, size_t b) const {
  const ViewLink* link = Find(a, b);
  return link == nullptr ? -1.0 : link->spread;
}

std::vector<size_t> ViewGraph::Neighbours(size_t camera) const {
  std::vector<size_t> out;
  for (const ViewLink& link : links_) {
    if (link.i == camera) out.push_back(link.j);
    if (link.j == camera) out.push_back(link.i);
  }
  std::sort(out.begin(), out.end());
  return out;
}

size_t CameraIndex(const std::vector<CameraModel>& cameras, const std::string& id) {
  return static_cast<size_t>(
      std::find_if(cameras.begin(), cameras.end(), [&](const auto& c) { return c.id == id; }) -
      cameras.begin());
}

ViewGraph BuildViewGraph(const std::vector<std::string>& camera_ids,
                         const std::vector<PairwiseResult>& pairs) {
  ViewGraph graph(camera_ids.size());
  const auto index_of = [&](const std::string& id) {
    return static_cast<size_t>(std::find(camera_ids.begin(), camera_ids.end(), id) -
                               camera_ids.begin());
  };
  for (const PairwiseResult& p : pairs) {
    const size_t i = index_of(p.camera_i), j = index_of(p.camera_j);
    if (p.status != PairStatus::kOk || i >= camera_ids.size() || j >= camera_ids.size() || i == j)
      continue;
    ViewLink link;
    link.i = i;
    link.j = j;
    link.F = p.F;
    link.spread = p.spread_score;
    link.matches.reserve(p.inlier_matches.size());
    for (const TimedMatch& m : p.inlier_matches) {
      link.matches.push_back({m.x_i, m.XjAt(p.offset), m.frame_i});
    }
    graph.Add(std::move(link));
  }
  return graph;
}

}  // namespace silnet::aggregator

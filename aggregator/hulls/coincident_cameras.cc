#include "aggregator/hulls/coincident_cameras.h"

#include <fmt/format.h>

#include <algorithm>

namespace silnet::aggregator {
namespace {

constexpr double kSameRelative = 1e-9;

// True if two cameras project every point alike.
bool SameProjection(const CameraModel& a, const CameraModel& b) {
  if (a.width != b.width || a.height != b.height) return false;
  if ((a.dist - b.dist).norm() > kSameRelative * (1 + a.dist.norm())) return false;
  const Matrix34d pa = a.ProjectionMatrix(), pb = b.ProjectionMatrix();
  return (pa / pa.norm() - pb / pb.norm()).norm() <= kSameRelative;
}

}  // namespace

CoincidentCameras FindCoincidentCameras(const std::vector<CameraModel>& cameras) {
  CoincidentCameras result;
  result.same_as.resize(cameras.size());
  double rig = 0;
  for (size_t a = 0; a < cameras.size(); ++a) {
    for (size_t b = a + 1; b < cameras.size(); ++b)
      rig = std::max(rig, (cameras[a].Center() - cameras[b].Center()).norm());
  }
  for (size_t v = 0; v < cameras.size(); ++v) {
    result.same_as[v] = static_cast<int>(v);
    for (size_t u = 0; u < v; ++u) {
      if (result.same_as[u] != static_cast<int>(u)) continue;
      if ((cameras[u].Center() - cameras[v].Center()).norm() > kSameRelative * rig) continue;
      if (SameProjection(cameras[u], cameras[v])) {
        result.same_as[v] = static_cast<int>(u);
        break;
      }
      if (result.conflict.empty()) {
        result.conflict = fmt::format(
            "cameras {} and {} stand at one centre but look differently: the exact hull needs "
            "distinct viewpoints",
            cameras[u].id, cameras[v].id);
      }
    }
  }
  return result;
}

}  // namespace silnet::aggregator

#include "aggregator/hulls/viewing_edges.h"

#include <algorithm>
#include <limits>
#include <optional>

#include "aggregator/hulls/cone_line_stretches.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// The viewing edges of the contour vertex that starts cone plane `plane`.
void RayEdges(const std::vector<Eigen::Vector3d>& centres, const ConePlaneSet& set,
              const WorldBox& bounds, int plane, ConeLineBuffers* buffers,
              std::vector<ViewingEdge>* out) {
  const ConePlane& face = set.Plane(plane);
  const ConeLine ray{face.view, centres[static_cast<size_t>(face.view)], set.RayThroughP(plane)};
  const std::optional<LineStretch> range =
      ClipToBox(ray, bounds, {0.0, std::numeric_limits<double>::infinity()});
  if (!range) return;
  StretchesInsideCones(set, centres, ray, *range, face.view, face.view, buffers);
  for (const LineStretch& s : buffers->inside)
    out->push_back({plane, face.view, s.lo, s.hi, s.lo_plane, s.hi_plane});
}

}  // namespace

std::vector<ViewingEdge> ComputeViewingEdges(const std::vector<CameraModel>& cameras,
                                             const ConePlaneSet& set, const WorldBox& bounds,
                                             int threads) {
  SILNET_CHECK(cameras.size() == set.Views());
  std::vector<Eigen::Vector3d> centres;
  for (const CameraModel& camera : cameras)
    centres.push_back(camera.Center());
  // Rays in chunks of consecutive planes, concatenated in plane order afterwards.
  const size_t planes = set.Planes().size();
  const size_t chunk = 256;
  const size_t chunks = (planes + chunk - 1) / chunk;
  std::vector<std::vector<ViewingEdge>> parts(chunks);
  ParallelFor(chunks, threads, [&](size_t k) {
    ConeLineBuffers buffers;
    const size_t end = std::min(planes, (k + 1) * chunk);
    for (size_t p = k * chunk; p < end; ++p)
      RayEdges(centres, set, bounds, static_cast<int>(p), &buffers, &parts[k]);
  });
  std::vector<ViewingEdge> edges;
  for (const std::vector<ViewingEdge>& part : parts)
    edges.insert(edges.end(), part.begin(), part.end());
  return edges;
}

Eigen::Vector3d ViewingEdgePoint(const std::vector<CameraModel>& cameras, const ConePlaneSet& set,
                                 const ViewingEdge& edge, double t) {
  return cameras[static_cast<size_t>(edge.view)].Center() + t * set.RayThroughP(edge.plane);
}

}  // namespace silnet::aggregator

#include "aggregator/stereo/tet_cell_labels.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "aggregator/stereo/tet_point_locator.h"
#include "aggregator/stereo/tet_ray_walk.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// The value at `percentile` (0..100) of `values` (not empty), nearest rank.
uint32_t Percentile(std::vector<uint32_t> values, double percentile) {
  const size_t k =
      std::min(values.size() - 1, static_cast<size_t>(percentile / 100 * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace

std::vector<CellLabel> LabelCells(const TetMesh& mesh, const std::vector<CellFace>& faces,
                                  const std::vector<int>& levels, int finest,
                                  const PatchScorer& scorer,
                                  const std::vector<CameraModel>& cameras,
                                  const std::vector<OrientedPoint>& points,
                                  const CellLabelOptions& options, CellLabelStats* stats,
                                  std::vector<uint32_t>* votes_out, const Progress* cancel) {
  SILNET_CHECK(levels.size() == mesh.tetrahedra.size());
  SILNET_CHECK(options.ray_step > 0);
  const size_t cells = mesh.tetrahedra.size();
  std::vector<CellLabel> labels(cells, CellLabel::kFree);
  std::vector<Eigen::Vector3d> centroid(cells);
  for (size_t t = 0; t < cells; ++t) {
    centroid[t] = Eigen::Vector3d::Zero();
    for (int32_t v : mesh.tetrahedra[t])
      centroid[t] += mesh.vertices[v] / 4;
  }
  ParallelFor(cells, options.threads, cancel, [&](size_t t) {
    if (!scorer.InsideSilhouettes(centroid[t])) labels[t] = CellLabel::kExterior;
  });
  CellLabelStats local;
  for (CellLabel l : labels)
    local.outside_hull += l == CellLabel::kExterior ? 1 : 0;

  // Votes along the rays from each point to the views that scored it, walked cell by cell.
  const TetPointLocator locator(mesh, 4 * options.ray_step);
  const TetRayWalker walker(mesh, faces);
  std::vector<std::atomic<uint32_t>> votes(cells);
  std::atomic<size_t> rays{0};
  ParallelFor(points.size(), options.threads, cancel, [&](size_t k) {
    const OrientedPoint& p = points[k];
    for (size_t v = 0; v < cameras.size() && v < 64; ++v) {
      if (((p.view_mask >> v) & 1) == 0) continue;
      ++rays;
      const Eigen::Vector3d direction = (cameras[v].Center() - p.point).normalized();
      const Eigen::Vector3d start = p.point + options.ray_start * direction;
      const int32_t first = locator.Locate(start);
      if (first < 0) continue;
      // Out of the hull the ray has left the cells that matter (it could enter again only
      // through a concavity of the hull itself).
      walker.Walk(first, start, direction, [&](int32_t t, double entry, double exit) {
        if (labels[static_cast<size_t>(t)] == CellLabel::kExterior) return false;
        if (exit - entry >= options.min_chord)
          votes[static_cast<size_t>(t)].fetch_add(1, std::memory_order_relaxed);
        return true;
      });
    }
  });
  if (cancel && cancel->cancelled()) return labels;
  local.rays = rays;

  std::vector<uint32_t> coarse_votes;
  for (size_t t = 0; t < cells; ++t)
    if (labels[t] == CellLabel::kFree && levels[t] < finest) coarse_votes.push_back(votes[t]);
  if (!coarse_votes.empty()) {
    const uint32_t interior_max =
        Percentile(coarse_votes, std::max(0.0, options.interior_percentile));
    const uint32_t exterior_min =
        options.exterior_percentile >= 100
            ? std::numeric_limits<uint32_t>::max()
            : std::max<uint32_t>(static_cast<uint32_t>(options.min_exterior_votes),
                                 Percentile(coarse_votes, options.exterior_percentile));
    for (size_t t = 0; t < cells; ++t) {
      if (labels[t] != CellLabel::kFree || levels[t] >= finest) continue;
      if (options.interior_percentile >= 0 && votes[t] <= interior_max) {
        labels[t] = CellLabel::kInterior;
        ++local.interior;
      } else if (votes[t] >= exterior_min) {
        labels[t] = CellLabel::kExterior;
        ++local.exterior_by_votes;
      }
    }
  }
  for (CellLabel l : labels)
    local.free += l == CellLabel::kFree ? 1 : 0;
  if (stats) *stats = local;
  if (votes_out) {
    votes_out->resize(cells);
    for (size_t t = 0; t < cells; ++t)
      (*votes_out)[t] = votes[t];
  }
  return labels;
}

}  // namespace silnet::aggregator

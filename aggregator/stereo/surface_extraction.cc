#include "aggregator/stereo/surface_extraction.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "aggregator/hulls/boundary_mesh.h"
#include "aggregator/stereo/taubin_smoothing.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {}  // namespace

bool SurfaceExtractionOptions::IsValid(std::string* reason) const {
  const auto fail = [reason](const char* why) {
    if (reason != nullptr) *reason = why;
    return false;
  };
  if (smoothing_iterations < 0) return fail("smoothing_iterations must be >= 0");
  if (!(smoothing_lambda > 0 && smoothing_lambda < 1))
    return fail("smoothing_lambda must lie in (0, 1)");
  if (!(smoothing_mu < 0 && -smoothing_mu > smoothing_lambda))
    return fail("smoothing_mu must be negative with |mu| > lambda");
  if (!(max_vertex_shift_cells >= 0)) return fail("max_vertex_shift_cells must be >= 0");
  return true;
}

namespace {

// Keeps the vertices at the corners of the `pinned` cells where they are (lo = hi = position).
void PinCellCorners(const VoxelGrid& grid, const std::vector<size_t>& pinned,
                    const std::vector<Eigen::Vector3f>& vertices, std::vector<Eigen::Vector3f>& lo,
                    std::vector<Eigen::Vector3f>& hi) {
  if (pinned.empty()) return;
  // Lattice corner (i, j, k) of each vertex, packed; cuberille vertices lie on corners.
  const auto nx = static_cast<int64_t>(grid.dims[0]) + 1,
             ny = static_cast<int64_t>(grid.dims[1]) + 1;
  const auto key = [nx, ny](int64_t i, int64_t j, int64_t k) { return (k * ny + j) * nx + i; };
  std::unordered_set<int64_t> corners;
  for (size_t c : pinned) {
    const auto cell = static_cast<int64_t>(c);
    const int64_t i = cell % grid.dims[0], j = (cell / grid.dims[0]) % grid.dims[1],
                  k = cell / (static_cast<int64_t>(grid.dims[0]) * grid.dims[1]);
    for (int d = 0; d < 8; ++d)
      corners.insert(key(i + (d & 1), j + ((d >> 1) & 1), k + ((d >> 2) & 1)));
  }
  for (size_t v = 0; v < vertices.size(); ++v) {
    const Eigen::Vector3d lattice = (vertices[v].cast<double>() - grid.origin) / grid.voxel_size;
    const auto i = static_cast<int64_t>(std::lround(lattice.x())),
               j = static_cast<int64_t>(std::lround(lattice.y())),
               k = static_cast<int64_t>(std::lround(lattice.z()));
    if (corners.count(key(i, j, k)) != 0) lo[v] = hi[v] = vertices[v];
  }
}

}  // namespace

TriangleMesh ExtractCutSurface(const VoxelGrid& interior, const SurfaceExtractionOptions& options,
                               const std::vector<size_t>& pinned) {
  std::string reason;
  SILNET_CHECK_MSG(options.IsValid(&reason), reason);
  TriangleMesh mesh = ExtractBoundaryMesh(interior);
  if (options.smoothing_iterations == 0 || mesh.vertices.empty()) return mesh;
  const float shift = static_cast<float>(options.max_vertex_shift_cells * interior.voxel_size);
  std::vector<Eigen::Vector3f> lo(mesh.vertices.size()), hi(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    lo[i] = mesh.vertices[i].array() - shift;
    hi[i] = mesh.vertices[i].array() + shift;
  }
  PinCellCorners(interior, pinned, mesh.vertices, lo, hi);
  TaubinSmooth(&mesh, options.smoothing_iterations, options.smoothing_lambda, options.smoothing_mu,
               lo, hi);
  return mesh;
}

}  // namespace silnet::aggregator

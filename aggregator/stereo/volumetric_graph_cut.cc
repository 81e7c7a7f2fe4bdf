#include "aggregator/stereo/volumetric_graph_cut.h"

#include <chrono>
#include <cstdio>

#include "aggregator/stereo/stereo_graph.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

bool VolumetricGraphCutOptions::IsValid(std::string* reason) const {
  const auto fail = [reason](const std::string& why) {
    if (reason != nullptr) *reason = why;
    return false;
  };
  if (!(lambda > 0)) return fail("lambda must be > 0");
  if (!(inner_offset_fraction > 0 && inner_offset_fraction < 1))
    return fail("inner_offset_fraction must lie in (0, 1)");
  if (!(inner_offset_cells >= 0)) return fail("inner_offset_cells must be >= 0");
  if (!(ballooning >= 0)) return fail("ballooning must be >= 0");
  std::string why;
  if (!surface.IsValid(&why)) return fail("surface: " + why);
  return true;
}

std::string VolumetricGraphCutStats::Brief() const {
  char line[512];
  std::snprintf(line, sizeof(line),
                "graph cut: %zu cells, hull %zu, pockets %zu, %zu nodes, %zu n-links, "
                "%zu t-link faces, d_max %.1f, offset %.1f cells, cut %.3g, graph %.1f MB, "
                "lattice %.1f MB; distance %.3f s, build %.3f s, max-flow %.3f s, labels %.3f s, "
                "surface %.3f s (%zu triangles)",
                lattice_cells, hull_cells, pocket_cells, nodes, n_links, t_link_faces,
                max_depth_cells, inner_offset_cells, cut_cost, graph_bytes / 1e6,
                lattice_bytes / 1e6, seconds_distance, seconds_build, seconds_max_flow,
                seconds_labels, seconds_surface, surface_triangles);
  return line;
}

VolumetricGraphCutResult VolumetricGraphCut(const VoteVolume& votes, const VoxelGrid& hull,
                                            const VolumetricGraphCutOptions& options) {
  std::string reason;
  SILNET_CHECK_MSG(options.IsValid(&reason), reason);
  SILNET_CHECK_MSG(SameLattice(hull, votes), "hull grid is not on the vote lattice");
  SILNET_CHECK(votes.votes.size() == votes.size() && hull.occupied.size() == hull.size());
  VolumetricGraphCutResult result;
  VolumetricGraphCutStats& stats = result.stats;
  stats.lattice_cells = votes.size();

  auto start = Clock::now();
  const StereoLattice lattice =
      ClassifyLattice(hull, options.inner_offset_fraction, options.inner_offset_cells);
  stats.seconds_distance = SecondsSince(start);
  stats.hull_cells = lattice.hull_cells;
  stats.pocket_cells = lattice.pocket_cells;
  stats.nodes = lattice.free_cells;
  stats.max_depth_cells = lattice.max_depth_cells;
  stats.inner_offset_cells = lattice.inner_offset_cells;
  if (lattice.hull_cells == 0) {
    result.reason = "the hull has no cell on the vote lattice";
    return result;
  }
  if (lattice.pocket_cells == 0) {
    char why[160];
    std::snprintf(why, sizeof(why),
                  "no hull cell is deeper than the inner offset (%.2f cells; deepest %.2f)",
                  lattice.inner_offset_cells, lattice.max_depth_cells);
    result.reason = why;
    return result;
  }

  start = Clock::now();
  StereoGraph graph = BuildStereoGraph(lattice, votes, options.lambda, options.ballooning);
  stats.seconds_build = SecondsSince(start);
  stats.n_links = graph.n_links;
  stats.t_link_faces = graph.source_faces + graph.sink_faces;
  stats.graph_bytes = graph.graph.MemoryBytes();
  // Roles, node index, labels, and the distance transform's floats (freed before the build).
  stats.lattice_bytes =
      lattice.roles.size() * (sizeof(CellRole) + sizeof(int32_t) + 1 + sizeof(float));

  start = Clock::now();
  stats.cut_cost = graph.graph.Solve() + graph.forced_cost;
  stats.seconds_max_flow = SecondsSince(start);

  start = Clock::now();
  result.interior = VoxelGrid::Empty(votes.origin, votes.cell_size, votes.dims);
  for (size_t c = 0; c < lattice.roles.size(); ++c) {
    const bool inside =
        lattice.roles[c] == CellRole::kPocket ||
        (lattice.roles[c] == CellRole::kFree && graph.graph.IsSourceSide(graph.node_of_cell[c]));
    result.interior.occupied[c] = inside ? 1 : 0;
    stats.interior_cells += inside ? 1 : 0;
  }
  stats.seconds_labels = SecondsSince(start);

  if (options.extract_surface) {
    start = Clock::now();
    result.surface = ExtractCutSurface(result.interior, options.surface);
    stats.seconds_surface = SecondsSince(start);
    stats.surface_triangles = result.surface.triangles.size();
  }
  result.success = true;
  return result;
}

VolumetricGraphCutResult VolumetricGraphCut(const VoteVolume& votes, const TriangleMesh& hull,
                                            const VolumetricGraphCutOptions& options) {
  return VolumetricGraphCut(votes, HullOnLattice(hull, votes), options);
}

}  // namespace silnet::aggregator

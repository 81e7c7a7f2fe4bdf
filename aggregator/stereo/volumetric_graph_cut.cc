#include "aggregator/stereo/volumetric_graph_cut.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <unordered_set>
#include <vector>

#include "aggregator/stereo/silhouette_repair.h"
#include "aggregator/stereo/steps_to_interior.h"
#include "aggregator/stereo/stereo_graph.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Calls fn(n) for the in-grid neighbours n of cell `c` of `grid`: the 6 that share a face,
// or with `all` the 26 that share a face, edge or corner.
template <typename Fn>
void ForEachNeighbour(const VoxelGrid& grid, size_t c, bool all, Fn&& fn) {
  const auto nx = static_cast<size_t>(grid.dims[0]), ny = static_cast<size_t>(grid.dims[1]);
  const auto i = static_cast<int>(c % nx), j = static_cast<int>((c / nx) % ny),
             k = static_cast<int>(c / (nx * ny));
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int steps = std::abs(di) + std::abs(dj) + std::abs(dk);
        if (steps == 0 || (!all && steps > 1) || !grid.InGrid(i + di, j + dj, k + dk)) continue;
        fn(grid.Index(i + di, j + dj, k + dk));
      }
}

// Labels result.interior from the solved `graph`: interior = the pockets of `lattice` and its
// free cells on the source side of the cut.
void LabelCells(const StereoLattice& lattice, const StereoGraph& graph,
                VolumetricGraphCutResult& result) {
  const auto start = Clock::now();
  for (size_t c = 0; c < lattice.roles.size(); ++c) {
    const bool inside =
        lattice.roles[c] == CellRole::kPocket ||
        (lattice.roles[c] == CellRole::kFree && graph.graph.IsSourceSide(graph.node_of_cell[c]));
    result.interior.occupied[c] = inside ? 1 : 0;
  }
  result.stats.seconds_labels += SecondsSince(start);
}

// The graph of stereo_graph.h for `lattice`, built and solved; its sizes, cut and times go to
// `stats`.
StereoGraph BuildAndSolve(const StereoLattice& lattice, const VoteVolume& votes,
                          const VolumetricGraphCutOptions& options,
                          VolumetricGraphCutStats& stats) {
  auto start = Clock::now();
  StereoGraph graph = BuildStereoGraph(lattice, votes, options.lambda, options.ballooning);
  stats.seconds_build += SecondsSince(start);
  stats.nodes = lattice.free_cells;
  stats.n_links = graph.n_links;
  stats.t_link_faces = graph.source_faces + graph.sink_faces;
  stats.graph_bytes = graph.graph.MemoryBytes();
  start = Clock::now();
  stats.cut_cost = graph.graph.Solve() + graph.forced_cost;
  stats.seconds_max_flow += SecondsSince(start);
  return graph;
}

// Ties the nodes of `cells` (free cells of the solved `graph`) to the source and updates the
// cut incrementally. The cut's capacity plus the graph's forced cost is the cost of the cut
// of the graph rebuilt with these cells as pockets (the forcing capacities are never cut).
void ForceAndResolve(const std::vector<size_t>& cells, StereoGraph& graph,
                     VolumetricGraphCutStats& stats) {
  const auto start = Clock::now();
  for (size_t c : cells)
    graph.graph.ForceSourceSide(graph.node_of_cell[c]);
  stats.cut_cost = graph.graph.Resolve() + graph.forced_cost;
  stats.seconds_max_flow += SecondsSince(start);
}

// Surface of result.interior into result.surface when the options need it, the corners of the
// `pinned` cells kept on the lattice.
void ExtractSurface(const VolumetricGraphCutOptions& options, const std::vector<size_t>& pinned,
                    VolumetricGraphCutResult& result) {
  if (!options.extract_surface && options.silhouette_rounds == 0) return;
  const auto start = Clock::now();
  result.surface = ExtractCutSurface(result.interior, options.surface, pinned);
  result.stats.seconds_surface += SecondsSince(start);
}

// Cells whose corners the cut's surface keeps on the lattice (pins), each once.
struct PinnedCells {
  std::vector<size_t> cells;
  std::unordered_set<size_t> set;

  // Adds `c`; false if it was pinned already.
  bool Pin(size_t c) {
    if (!set.insert(c).second) return false;
    cells.push_back(c);
    return true;
  }
};

// What the silhouette step does for each cell of `repair` (the cell chosen on a missed
// pixel's ray): a free cell is tied to the source (marked as a pocket in `lattice`, returned);
// an interior cell the surface still misses was smoothed away and is pinned; a pinned one
// still missed (a lone cell, a thin line) brings its free face neighbours in the hull, else
// its 26 neighbours.
std::vector<size_t> RepairCells(const SilhouetteRepair& repair, const VoxelGrid& hull,
                                StereoLattice& lattice, PinnedCells& pinned) {
  std::vector<size_t> added;
  const auto force = [&lattice, &added](size_t c) {
    if (lattice.roles[c] != CellRole::kFree) return;
    lattice.roles[c] = CellRole::kPocket;
    --lattice.free_cells;
    ++lattice.pocket_cells;
    added.push_back(c);
  };
  for (size_t c : repair.cells) {
    if (lattice.roles[c] == CellRole::kFree) {
      force(c);
      continue;
    }
    if (pinned.Pin(c)) continue;
    const size_t before = added.size();
    ForEachNeighbour(hull, c, false, force);
    if (added.size() == before) ForEachNeighbour(hull, c, true, force);
  }
  return added;
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
  if (silhouette_rounds < 0) return fail("silhouette_rounds must be >= 0");
  if (silhouette_join_steps < 0 || silhouette_join_steps > StepsToInterior::kMaxSteps)
    return fail(fmt::format("silhouette_join_steps must lie in 0..{}", StepsToInterior::kMaxSteps));
  if (!(silhouette_margin_px >= 0)) return fail("silhouette_margin_px must be >= 0");
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
  std::string brief = line;
  if (!missed_pixels_per_round.empty()) {
    brief += fmt::format(
        "; silhouette step: {} rounds, {} cells forced, {} pinned, {} pixels' cells joined to "
        "the interior, missed inner pixels {} ({:.3f} s)",
        silhouette_rounds, forced_cells, pinned_cells, joined_pixels,
        fmt::join(missed_pixels_per_round, " "), seconds_silhouette_step);
  }
  return brief;
}

StereoLattice ClassifyHullCells(const VoxelGrid& hull, const VolumetricGraphCutOptions& options,
                                VolumetricGraphCutStats& stats) {
  const auto start = Clock::now();
  StereoLattice lattice =
      ClassifyLattice(hull, options.inner_offset_fraction, options.inner_offset_cells);
  stats.seconds_distance = SecondsSince(start);
  stats.hull_cells = lattice.hull_cells;
  stats.pocket_cells = lattice.pocket_cells;
  stats.max_depth_cells = lattice.max_depth_cells;
  stats.inner_offset_cells = lattice.inner_offset_cells;
  return lattice;
}

VolumetricGraphCutResult VolumetricGraphCut(const VoteVolume& votes, const VoxelGrid& hull,
                                            const VolumetricGraphCutOptions& options,
                                            const CutSilhouettes* silhouettes,
                                            const Progress* cancel) {
  std::string reason;
  SILNET_CHECK_MSG(options.IsValid(&reason), reason);
  SILNET_CHECK_MSG(SameLattice(hull, votes), "hull grid is not on the vote lattice");
  SILNET_CHECK(votes.votes.size() == votes.size() && hull.occupied.size() == hull.size());
  VolumetricGraphCutResult result;
  VolumetricGraphCutStats& stats = result.stats;
  stats.lattice_cells = votes.size();
  // True (with the reason set) once `cancel` is cancelled.
  const auto cancelled = [&] {
    if (!cancel || !cancel->cancelled()) return false;
    result.reason = "cancelled";
    return true;
  };

  StereoLattice lattice = ClassifyHullCells(hull, options, stats);
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

  // Roles, node index, labels, and the distance transform's floats (freed before the build).
  stats.lattice_bytes =
      lattice.roles.size() * (sizeof(CellRole) + sizeof(int32_t) + 1 + sizeof(float));
  SILNET_CHECK_MSG(silhouettes != nullptr || options.silhouette_rounds == 0,
                   "the silhouette step needs the silhouettes");
  // The graph is built and solved once. Each silhouette step marks the cells it forces as
  // pockets in `lattice` (the labels) and ties their nodes to the source in the graph, whose
  // cut is then updated from the previous flow instead of being rebuilt.
  StereoGraph graph = BuildAndSolve(lattice, votes, options, stats);
  if (cancelled()) return result;
  result.interior = VoxelGrid::Empty(votes.origin, votes.cell_size, votes.dims);
  LabelCells(lattice, graph, result);
  PinnedCells pinned;
  ExtractSurface(options, pinned.cells, result);
  for (int round = 0; round < options.silhouette_rounds; ++round) {
    if (cancelled()) return result;
    const auto start = Clock::now();
    std::optional<StepsToInterior> steps;
    if (options.silhouette_join_steps > 0)
      steps = StepsToInterior::Compute(hull, result.interior, options.silhouette_join_steps);
    const SilhouetteRepair repair =
        FindSilhouetteRepair(result.surface, hull, votes, silhouettes->cameras, silhouettes->masks,
                             options.silhouette_margin_px, steps ? &*steps : nullptr);
    stats.seconds_silhouette_step += SecondsSince(start);
    stats.missed_pixels_per_round.push_back(repair.missed_pixels);
    stats.joined_pixels += repair.joined;
    const size_t pins_before = pinned.cells.size();
    const std::vector<size_t> added = RepairCells(repair, hull, lattice, pinned);
    stats.forced_cells += added.size();
    if (added.empty() && pinned.cells.size() == pins_before) break;
    ++stats.silhouette_rounds;
    if (!added.empty()) {
      ForceAndResolve(added, graph, stats);
      LabelCells(lattice, graph, result);
    }
    ExtractSurface(options, pinned.cells, result);
  }
  if (cancelled()) return result;
  stats.pinned_cells = pinned.cells.size();
  for (uint8_t inside : result.interior.occupied)
    stats.interior_cells += inside;
  stats.surface_triangles = result.surface.triangles.size();
  result.success = true;
  return result;
}

VolumetricGraphCutResult VolumetricGraphCut(const VoteVolume& votes, const TriangleMesh& hull,
                                            const VolumetricGraphCutOptions& options,
                                            const CutSilhouettes* silhouettes,
                                            const Progress* cancel) {
  return VolumetricGraphCut(votes, HullOnLattice(hull, votes), options, silhouettes, cancel);
}

}  // namespace silnet::aggregator

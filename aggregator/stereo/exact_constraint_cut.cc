#include "aggregator/stereo/exact_constraint_cut.h"

#include <chrono>
#include <cmath>

#include "aggregator/stereo/exact_constraint_graph.h"
#include "aggregator/stereo/stereo_graph.h"
#include "aggregator/stereo/surface_extraction.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Photo-consistency of a segment from the votes: 1 - 2 exp(-lambda * v) for the most voted
// cell along it (sampled every half cell), in [-1, 1) as the rim graph expects.
SegmentPhotoConsistency VotedPhotoConsistency(const VoteVolume& votes, double lambda) {
  return [&votes, lambda](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const int samples = 1 + static_cast<int>(std::ceil(2 * (b - a).norm() / votes.cell_size));
    float most = 0;
    for (int s = 0; s <= samples; ++s) {
      if (const auto cell = votes.CellOf(a + (b - a) * (static_cast<double>(s) / samples)))
        most = std::max(most, votes.votes[votes.Index((*cell)[0], (*cell)[1], (*cell)[2])]);
    }
    return 1 - 2 * std::exp(-lambda * most);
  };
}

}  // namespace

ExactConstraintCutResult ExactConstraintCut(const VoteVolume& votes, const VoxelGrid& hull_cells,
                                            const PolyhedralHullResult& hull,
                                            const CutSilhouettes& views,
                                            const VolumetricGraphCutOptions& options,
                                            const Progress* cancel) {
  SILNET_CHECK_MSG(hull.provenance.vertex_planes.size() == hull.mesh.vertices.size() &&
                       !hull.provenance.planes.empty(),
                   "the exact constraints need the hull's provenance");
  SILNET_CHECK_MSG(SameLattice(hull_cells, votes), "hull grid is not on the vote lattice");
  ExactConstraintCutResult result;
  VolumetricGraphCutResult& cut = result.cut;
  VolumetricGraphCutStats& stats = cut.stats;
  stats.lattice_cells = votes.size();

  const StereoLattice lattice = ClassifyHullCells(hull_cells, options, stats);
  if (lattice.hull_cells == 0 || lattice.pocket_cells == 0) {
    cut.reason = lattice.hull_cells == 0 ? "the hull has no cell on the vote lattice"
                                         : "no hull cell is deeper than the inner offset";
    return result;
  }

  auto start = Clock::now();
  const HullColouring colouring =
      ColourHullVertices(hull.mesh, hull.provenance, views.cameras, views.masks,
                         VotedPhotoConsistency(votes, options.lambda));
  const SurfaceLayer layer =
      ColourSurfaceLayer(lattice, votes, hull.mesh, hull.provenance, colouring);
  ExactConstraintStats& exact = result.exact;
  exact.colouring = colouring.stats;
  exact.layer_cells = layer.cells;
  exact.red_cells = layer.red_cells;
  exact.blue_cells = layer.blue_cells;
  exact.clashes = layer.clashes;
  exact.seconds_colouring = SecondsSince(start);
  if (cancel && cancel->cancelled()) {
    cut.reason = "cancelled";
    return result;
  }

  start = Clock::now();
  ExactConstraintGraph graph =
      BuildExactConstraintGraph(lattice, votes, layer, options.lambda, options.ballooning);
  stats.seconds_build = SecondsSince(start);
  stats.nodes = static_cast<size_t>(graph.graph.num_nodes());
  stats.n_links = graph.n_links;
  stats.t_link_faces = graph.terminal_links;
  stats.graph_bytes = graph.graph.MemoryBytes();
  stats.lattice_bytes = votes.size() * (sizeof(CellRole) + 3 * sizeof(int32_t) + 2);
  start = Clock::now();
  stats.cut_cost = graph.graph.Solve();
  stats.seconds_max_flow = SecondsSince(start);
  if (cancel && cancel->cancelled()) {
    cut.reason = "cancelled";
    return result;
  }

  start = Clock::now();
  cut.interior = ExactConstraintInterior(lattice, votes, graph);
  for (size_t c = 0; c < votes.size(); ++c) {
    stats.interior_cells += cut.interior.occupied[c];
    if (graph.first[c] >= 0 && !graph.graph.IsSourceSide(graph.first[c]) &&
        graph.graph.IsSourceSide(graph.second[c]))
      ++exact.twisted_cells;
  }
  stats.seconds_labels = SecondsSince(start);
  start = Clock::now();
  cut.surface = ExtractCutSurface(cut.interior, options.surface);
  stats.seconds_surface = SecondsSince(start);
  stats.surface_triangles = cut.surface.triangles.size();
  cut.success = true;
  return result;
}

}  // namespace silnet::aggregator

#include "aggregator/stereo/exact_constraint_graph.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

// A terminal link no minimum cut should take: far above any face's capacity (<= 1).
constexpr double kTied = 1e9;

constexpr std::array<std::array<int, 3>, 6> kSteps = {
    {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}};

// Calls `visit(n, inside)` for the six face neighbours of cell (i, j, k): `n` their index
// (0 beyond the grid) and `inside` whether they lie in the grid.
template <typename Visit>
void ForNeighbours(const VoteVolume& votes, int i, int j, int k, Visit visit) {
  for (const auto& step : kSteps) {
    const int ni = i + step[0], nj = j + step[1], nk = k + step[2];
    const bool inside = votes.InGrid(ni, nj, nk);
    visit(inside ? votes.Index(ni, nj, nk) : size_t{0}, inside);
  }
}

// The layer cell nearest to `p` among the cell it falls in and its 26 neighbours, or -1.
int64_t NearestLayerCell(const VoteVolume& votes, const std::vector<uint8_t>& in_layer,
                         const Eigen::Vector3d& p) {
  const Eigen::Vector3d local = (p - votes.origin) / votes.cell_size;
  const int ci = static_cast<int>(std::floor(local.x()));
  const int cj = static_cast<int>(std::floor(local.y()));
  const int ck = static_cast<int>(std::floor(local.z()));
  int64_t best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int dk = -1; dk <= 1; ++dk) {
    for (int dj = -1; dj <= 1; ++dj) {
      for (int di = -1; di <= 1; ++di) {
        const int i = ci + di, j = cj + dj, k = ck + dk;
        if (!votes.InGrid(i, j, k) || in_layer[votes.Index(i, j, k)] == 0) continue;
        const double d = (votes.Center(i, j, k) - p).squaredNorm();
        if (d < best_distance) {
          best_distance = d;
          best = static_cast<int64_t>(votes.Index(i, j, k));
        }
      }
    }
  }
  return best;
}

// True if the mesh edge a-b is a cone-intersection edge: its ends share faces of two views.
bool IsConeIntersectionEdge(const HullProvenance& provenance, int a, int b) {
  const std::vector<int>& pa = provenance.vertex_planes[static_cast<size_t>(a)];
  const std::vector<int>& pb = provenance.vertex_planes[static_cast<size_t>(b)];
  int first_view = -1;
  for (const int plane : pa) {
    if (!std::binary_search(pb.begin(), pb.end(), plane)) continue;
    const int view = provenance.planes[static_cast<size_t>(plane)].view;
    if (first_view < 0) {
      first_view = view;
    } else if (view != first_view) {
      return true;
    }
  }
  return false;
}

}  // namespace

SurfaceLayer ColourSurfaceLayer(const StereoLattice& lattice, const VoteVolume& votes,
                                const TriangleMesh& hull, const HullProvenance& provenance,
                                const HullColouring& colouring) {
  SILNET_CHECK(lattice.roles.size() == votes.size());
  SILNET_CHECK(colouring.colours.size() == hull.vertices.size() &&
               provenance.vertex_planes.size() == hull.vertices.size());
  SurfaceLayer layer;
  layer.in_layer.assign(votes.size(), 0);
  for (int k = 0; k < votes.dims[2]; ++k) {
    for (int j = 0; j < votes.dims[1]; ++j) {
      for (int i = 0; i < votes.dims[0]; ++i) {
        const size_t c = votes.Index(i, j, k);
        if (lattice.roles[c] != CellRole::kOutside) continue;
        bool touches = false;
        ForNeighbours(votes, i, j, k, [&](size_t n, bool inside) {
          touches = touches || (inside && lattice.roles[n] != CellRole::kOutside);
        });
        if (touches) {
          layer.in_layer[c] = 1;
          ++layer.cells;
        }
      }
    }
  }
  // Bit 1: a red point marked the cell, bit 2: a blue one.
  std::vector<uint8_t> marks(votes.size(), 0);
  const auto mark = [&](const Eigen::Vector3d& p, HullVertexColour colour) {
    const int64_t cell = NearestLayerCell(votes, layer.in_layer, p);
    if (cell >= 0) marks[static_cast<size_t>(cell)] |= colour == HullVertexColour::kRed ? 1 : 2;
  };
  for (size_t v = 0; v < hull.vertices.size(); ++v) {
    if (colouring.colours[v] != HullVertexColour::kGreen)
      mark(hull.vertices[v].cast<double>(), colouring.colours[v]);
  }
  for (const auto& t : hull.triangles) {
    for (size_t e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      if (a > b) continue;  // each edge once (closed mesh: the other triangle has b -> a)
      const HullVertexColour colour = colouring.colours[static_cast<size_t>(a)];
      if (colour == HullVertexColour::kGreen ||
          colour != colouring.colours[static_cast<size_t>(b)] ||
          !IsConeIntersectionEdge(provenance, a, b))
        continue;
      const Eigen::Vector3d pa = hull.vertices[static_cast<size_t>(a)].cast<double>();
      const Eigen::Vector3d pb = hull.vertices[static_cast<size_t>(b)].cast<double>();
      const int samples = 1 + static_cast<int>(std::ceil(4 * (pb - pa).norm() / votes.cell_size));
      for (int s = 0; s <= samples; ++s)
        mark(pa + (pb - pa) * (static_cast<double>(s) / samples), colour);
    }
  }
  layer.terminal.assign(votes.size(), 0);
  for (size_t c = 0; c < marks.size(); ++c) {
    if (marks[c] == 1) {
      layer.terminal[c] = 1;
      ++layer.red_cells;
    } else if (marks[c] == 2) {
      layer.terminal[c] = -1;
      ++layer.blue_cells;
    } else if (marks[c] == 3) {
      ++layer.clashes;
    }
  }
  return layer;
}

ExactConstraintGraph BuildExactConstraintGraph(const StereoLattice& lattice,
                                               const VoteVolume& votes, const SurfaceLayer& layer,
                                               double lambda, double ballooning) {
  SILNET_CHECK(lattice.dims == votes.dims && lattice.roles.size() == votes.size() &&
               layer.in_layer.size() == votes.size() && layer.terminal.size() == votes.size());
  SILNET_CHECK(lambda > 0 && ballooning >= 0);
  const size_t nodes = 2 * lattice.free_cells + layer.cells;
  SILNET_CHECK_MSG(nodes < static_cast<size_t>(std::numeric_limits<int>::max()),
                   "exact-constraint graph has " << nodes << " nodes, max 2^31 - 1");
  ExactConstraintGraph g;
  g.graph = MaxFlowGraph(static_cast<int64_t>(nodes), 6 * static_cast<int64_t>(nodes));
  g.first.assign(votes.size(), -1);
  g.second.assign(votes.size(), -1);
  g.surface.assign(votes.size(), -1);
  if (nodes == 0) return g;
  g.graph.AddNodes(static_cast<int>(nodes));
  const int free_cells = static_cast<int>(lattice.free_cells);
  int next_free = 0, next_layer = 2 * free_cells;
  for (size_t c = 0; c < votes.size(); ++c) {
    if (lattice.roles[c] == CellRole::kFree) {
      g.first[c] = next_free;
      g.second[c] = next_free + free_cells;
      ++next_free;
    } else if (layer.in_layer[c] != 0) {
      g.surface[c] = next_layer++;
    }
  }
  const auto face = [&](size_t a, size_t b) {
    return std::exp(-lambda * 0.5 * (votes.votes[a] + votes.votes[b]));
  };
  const auto edge = [&](int a, int b, double w) {
    g.graph.AddEdge(a, b, w, w);
    ++g.n_links;
  };
  const auto terminal = [&](int node, double source, double sink) {
    g.graph.AddTerminalCapacities(node, source, sink);
    ++g.terminal_links;
  };
  for (int k = 0; k < votes.dims[2]; ++k) {
    for (int j = 0; j < votes.dims[1]; ++j) {
      for (int i = 0; i < votes.dims[0]; ++i) {
        const size_t c = votes.Index(i, j, k);
        if (g.first[c] >= 0) {
          if (ballooning > 0) {
            terminal(g.first[c], ballooning, 0);
            terminal(g.second[c], 0, ballooning);
          }
          ForNeighbours(votes, i, j, k, [&](size_t n, bool inside) {
            const double w = inside ? face(c, n) : std::exp(-lambda * 0.5 * votes.votes[c]);
            if (!inside) {  // beyond the lattice: exterior in both copies
              terminal(g.first[c], 0, w);
              terminal(g.second[c], 0, w);
            } else if (lattice.roles[n] == CellRole::kPocket) {
              terminal(g.first[c], w, 0);
              terminal(g.second[c], 0, w);
            } else if (g.surface[n] >= 0) {
              edge(g.first[c], g.surface[n], w);
              edge(g.second[c], g.surface[n], w);
            } else if (g.first[n] >= 0 && n > c) {
              edge(g.first[c], g.first[n], w);
              edge(g.second[c], g.second[n], w);
            }
          });
        } else if (g.surface[c] >= 0) {
          ForNeighbours(votes, i, j, k, [&](size_t n, bool inside) {
            if (!inside) return;
            if (g.surface[n] >= 0 && n > c) edge(g.surface[c], g.surface[n], face(c, n));
            // A pocket touching the hull's outside (a thin hull): source in the first copy's
            // sense, sink in the second's, on the one shared node.
            if (lattice.roles[n] == CellRole::kPocket)
              terminal(g.surface[c], face(c, n), face(c, n));
          });
          if (layer.terminal[c] != 0)
            terminal(g.surface[c], layer.terminal[c] > 0 ? kTied : 0,
                     layer.terminal[c] < 0 ? kTied : 0);
        }
      }
    }
  }
  return g;
}

VoxelGrid ExactConstraintInterior(const StereoLattice& lattice, const VoteVolume& votes,
                                  const ExactConstraintGraph& graph) {
  VoxelGrid interior = VoxelGrid::Empty(votes.origin, votes.cell_size, votes.dims);
  for (size_t c = 0; c < votes.size(); ++c) {
    if (lattice.roles[c] == CellRole::kPocket) {
      interior.occupied[c] = 1;
    } else if (graph.first[c] >= 0) {
      interior.occupied[c] =
          graph.graph.IsSourceSide(graph.first[c]) && !graph.graph.IsSourceSide(graph.second[c])
              ? 1
              : 0;
    }
  }
  return interior;
}

}  // namespace silnet::aggregator

#include "aggregator/stereo/stereo_graph.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "aggregator/hulls/mesh_measure.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

constexpr float kUnreached = std::numeric_limits<float>::infinity();

// Scratch space of the 1D transform, reused along all lines.
struct EnvelopeScratch {
  std::vector<int> sites;      // positions of the parabolas in the lower envelope
  std::vector<double> bounds;  // bounds[k]..bounds[k + 1]: where parabola k is lowest
  std::vector<float> line;     // the line being transformed
  std::vector<float> out;      // its transform
};

// In place: line[x] = min over sites q of (x - q)^2 + line[q], over the finite entries of
// `line` and two extra sites with value 0 at -1 and n (the outside beyond the grid).
void TransformLine(EnvelopeScratch& s) {
  std::vector<float>& f = s.line;
  const int n = static_cast<int>(f.size());
  const auto value = [&](int q) -> double { return q < 0 || q >= n ? 0.0 : f[q]; };
  const auto crossing = [&](int p, int q) {  // where parabolas of sites p < q meet
    return ((value(q) + double(q) * q) - (value(p) + double(p) * p)) / (2.0 * (q - p));
  };
  s.sites.assign(1, -1);
  s.bounds.assign(1, -std::numeric_limits<double>::infinity());
  for (int q = 0; q <= n; ++q) {
    if (q < n && f[q] == kUnreached) continue;
    double x = crossing(s.sites.back(), q);
    while (x <= s.bounds.back()) {
      s.sites.pop_back();
      s.bounds.pop_back();
      x = crossing(s.sites.back(), q);
    }
    s.sites.push_back(q);
    s.bounds.push_back(x);
  }
  s.bounds.push_back(std::numeric_limits<double>::infinity());
  std::vector<float>& out = s.out;
  out.resize(f.size());
  size_t k = 0;
  for (int x = 0; x < n; ++x) {
    while (s.bounds[k + 1] < x)
      ++k;
    const double d = x - s.sites[k];
    out[static_cast<size_t>(x)] = static_cast<float>(d * d + value(s.sites[k]));
  }
  f.swap(out);
}

}  // namespace

std::vector<float> SquaredDistanceToOutside(const VoxelGrid& occupancy) {
  const std::array<int, 3>& dims = occupancy.dims;
  std::vector<float> d(occupancy.size());
  for (size_t c = 0; c < d.size(); ++c)
    d[c] = occupancy.occupied[c] != 0 ? kUnreached : 0.0f;
  const std::array<size_t, 3> stride = {
      1, static_cast<size_t>(dims[0]), static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1])};
  EnvelopeScratch scratch;
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    const size_t n = static_cast<size_t>(dims[static_cast<size_t>(axis)]);
    for (int u = 0; u < dims[static_cast<size_t>(a1)]; ++u) {
      for (int v = 0; v < dims[static_cast<size_t>(a2)]; ++v) {
        const size_t start = static_cast<size_t>(u) * stride[static_cast<size_t>(a1)] +
                             static_cast<size_t>(v) * stride[static_cast<size_t>(a2)];
        const size_t step = stride[static_cast<size_t>(axis)];
        scratch.line.resize(n);
        for (size_t x = 0; x < n; ++x)
          scratch.line[x] = d[start + x * step];
        TransformLine(scratch);
        for (size_t x = 0; x < n; ++x)
          d[start + x * step] = scratch.line[x];
      }
    }
  }
  return d;
}

StereoLattice ClassifyLattice(const VoxelGrid& hull, double inner_offset_fraction,
                              double inner_offset_cells) {
  const std::vector<float> squared = SquaredDistanceToOutside(hull);
  StereoLattice lattice;
  lattice.dims = hull.dims;
  lattice.roles.assign(hull.size(), CellRole::kOutside);
  float max_squared = 0;
  for (size_t c = 0; c < squared.size(); ++c) {
    if (hull.occupied[c] != 0) max_squared = std::max(max_squared, squared[c]);
  }
  lattice.max_depth_cells = std::sqrt(static_cast<double>(max_squared));
  lattice.inner_offset_cells =
      inner_offset_cells > 0 ? inner_offset_cells : inner_offset_fraction * lattice.max_depth_cells;
  const double threshold = lattice.inner_offset_cells * lattice.inner_offset_cells;
  for (size_t c = 0; c < squared.size(); ++c) {
    if (hull.occupied[c] == 0) continue;
    ++lattice.hull_cells;
    if (static_cast<double>(squared[c]) > threshold) {
      lattice.roles[c] = CellRole::kPocket;
      ++lattice.pocket_cells;
    } else {
      lattice.roles[c] = CellRole::kFree;
      ++lattice.free_cells;
    }
  }
  return lattice;
}

VoxelGrid HullOnLattice(const TriangleMesh& hull, const VoteVolume& votes) {
  return RasterizeMesh(hull, VoxelGrid::Empty(votes.origin, votes.cell_size, votes.dims));
}

bool SameLattice(const VoxelGrid& grid, const VoteVolume& votes) {
  if (grid.dims != votes.dims || votes.cell_size <= 0) return false;
  const double tolerance = 1e-9 * votes.cell_size;
  return std::abs(grid.voxel_size - votes.cell_size) <= tolerance &&
         (grid.origin - votes.origin).cwiseAbs().maxCoeff() <= tolerance;
}

StereoGraph BuildStereoGraph(const StereoLattice& lattice, const VoteVolume& votes, double lambda,
                             double ballooning) {
  SILNET_CHECK(lattice.dims == votes.dims && lattice.roles.size() == votes.size() &&
               votes.votes.size() == votes.size());
  SILNET_CHECK(lambda > 0 && ballooning >= 0);
  SILNET_CHECK_MSG(lattice.free_cells < static_cast<size_t>(std::numeric_limits<int>::max()),
                   "graph cut lattice has " << lattice.free_cells << " free cells, max 2^31 - 1");
  StereoGraph g;
  g.graph = MaxFlowGraph(static_cast<int64_t>(lattice.free_cells),
                         3 * static_cast<int64_t>(lattice.free_cells));
  g.node_of_cell.assign(lattice.roles.size(), -1);
  if (lattice.free_cells == 0) return g;
  g.graph.AddNodes(static_cast<int>(lattice.free_cells));
  int next = 0;
  for (size_t c = 0; c < lattice.roles.size(); ++c) {
    if (lattice.roles[c] == CellRole::kFree) g.node_of_cell[c] = next++;
  }
  const std::array<int, 3>& dims = lattice.dims;
  // Capacity of the face between a cell with `a` votes and one with `b`.
  const auto face = [lambda](double a, double b) { return std::exp(-lambda * 0.5 * (a + b)); };
  constexpr std::array<std::array<int, 3>, 6> kSteps = {
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}}};
  for (int k = 0; k < dims[2]; ++k) {
    for (int j = 0; j < dims[1]; ++j) {
      for (int i = 0; i < dims[0]; ++i) {
        const size_t c = votes.Index(i, j, k);
        const CellRole role = lattice.roles[c];
        if (role == CellRole::kOutside) continue;
        const double vc = votes.votes[c];
        double to_source = role == CellRole::kFree ? ballooning : 0.0;
        double to_sink = 0;
        for (const auto& step : kSteps) {
          const int ni = i + step[0], nj = j + step[1], nk = k + step[2];
          const bool inside = votes.InGrid(ni, nj, nk);
          const size_t n = inside ? votes.Index(ni, nj, nk) : 0;
          const CellRole other = inside ? lattice.roles[n] : CellRole::kOutside;
          const double w = face(vc, inside ? votes.votes[n] : 0.0);
          if (role == CellRole::kPocket) {
            if (other == CellRole::kOutside) {
              ++g.forced_faces;
              g.forced_cost += w;
            }
            continue;
          }
          if (other == CellRole::kOutside) {
            to_sink += w;
            ++g.sink_faces;
          } else if (other == CellRole::kPocket) {
            to_source += w;
            ++g.source_faces;
          } else if (n > c) {
            g.graph.AddEdge(g.node_of_cell[c], g.node_of_cell[n], w, w);
            ++g.n_links;
          }
        }
        if (role == CellRole::kFree && (to_source > 0 || to_sink > 0)) {
          g.graph.AddTerminalCapacities(g.node_of_cell[c], to_source, to_sink);
        }
      }
    }
  }
  return g;
}

}  // namespace silnet::aggregator

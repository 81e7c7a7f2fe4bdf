// The baseline volumetric graph cut on synthetic vote volumes with known shapes: a sphere of
// votes inside a larger spherical hull, a cube with a dent inside a convex box hull (the hull
// fills the dent, the cut must recover it), the ballooning term, the distance transform
// against brute force, incremental re-solves against rebuilt graphs, failures as data, and
// sizes and times on a 128^3 lattice.

#include "aggregator/stereo/volumetric_graph_cut.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>

#include "aggregator/hulls/mesh_check.h"
#include "aggregator/hulls/ply_io.h"
#include "aggregator/stereo/stereo_graph.h"
#include "aggregator/stereo/surface_extraction.h"
#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

constexpr double kCell = 0.01;  // metres

VoteVolume Lattice(int n) {
  VoteVolume v;
  v.origin = Eigen::Vector3d(-0.2, 0.1, 0.3);
  v.cell_size = kCell;
  v.dims = {n, n, n};
  v.votes.assign(v.size(), 0.0f);
  return v;
}

// Cell-centre position in cell units, relative to the lattice corner.
Eigen::Vector3d CellCentre(int i, int j, int k) {
  return Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
}

// Occupancy on `votes`' lattice of the cells whose centres satisfy `inside` (cell units).
VoxelGrid GridOf(const VoteVolume& votes,
                 const std::function<bool(const Eigen::Vector3d&)>& inside) {
  VoxelGrid grid = VoxelGrid::Empty(votes.origin, votes.cell_size, votes.dims);
  for (int k = 0; k < votes.dims[2]; ++k)
    for (int j = 0; j < votes.dims[1]; ++j)
      for (int i = 0; i < votes.dims[0]; ++i)
        grid.occupied[grid.Index(i, j, k)] = inside(CellCentre(i, j, k)) ? 1 : 0;
  return grid;
}

// Votes on a spherical shell of radius `r` cells around `centre` (cells whose centres lie
// within 0.75 cells of it), `coverage` of them voted with 5..15 votes, plus sparse clutter.
void VoteSphere(VoteVolume& votes, const Eigen::Vector3d& centre, double r, double coverage,
                std::mt19937_64& rng) {
  std::bernoulli_distribution voted(coverage), clutter(0.03);
  std::uniform_real_distribution<float> strong(5, 15), weak(0.5f, 2.0f);
  for (int k = 0; k < votes.dims[2]; ++k)
    for (int j = 0; j < votes.dims[1]; ++j)
      for (int i = 0; i < votes.dims[0]; ++i) {
        float& v = votes.votes[votes.Index(i, j, k)];
        if (std::abs((CellCentre(i, j, k) - centre).norm() - r) < 0.75 && voted(rng)) {
          v = strong(rng);
        } else if (clutter(rng)) {
          v = weak(rng);
        }
      }
}

TEST(SquaredDistanceToOutside, MatchesBruteForce) {
  std::mt19937_64 rng(7);
  std::bernoulli_distribution occupied(0.85);
  VoxelGrid grid = VoxelGrid::Empty(Eigen::Vector3d::Zero(), 1.0, {12, 9, 7});
  for (auto& o : grid.occupied)
    o = occupied(rng) ? 1 : 0;
  const std::vector<float> d = SquaredDistanceToOutside(grid);
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 12; ++i) {
        const size_t c = grid.Index(i, j, k);
        // Nearest cell beyond the grid: straight out through the nearest side.
        int best = std::min({i + 1, 12 - i, j + 1, 9 - j, k + 1, 7 - k});
        best *= best;
        if (grid.occupied[c] == 0) best = 0;
        for (int z = 0; z < 7; ++z)
          for (int y = 0; y < 9; ++y)
            for (int x = 0; x < 12; ++x)
              if (grid.occupied[grid.Index(x, y, z)] == 0)
                best = std::min(best, (x - i) * (x - i) + (y - j) * (y - j) + (z - k) * (z - k));
        ASSERT_EQ(d[c], static_cast<float>(best)) << i << " " << j << " " << k;
      }
}

TEST(ClassifyLattice, PocketsBeyondTheInnerOffset) {
  const VoteVolume votes = Lattice(20);
  const VoxelGrid box = GridOf(votes, [](const Eigen::Vector3d& p) {
    return (p.array() > 2).all() && (p.array() < 18).all();
  });
  // Box cells 2..17: depth = distance to the nearest side + 1, deepest 8.
  const StereoLattice fraction = ClassifyLattice(box, 0.4, 0);
  EXPECT_EQ(fraction.hull_cells, 16u * 16u * 16u);
  EXPECT_DOUBLE_EQ(fraction.max_depth_cells, 8.0);
  EXPECT_DOUBLE_EQ(fraction.inner_offset_cells, 3.2);
  EXPECT_EQ(fraction.pocket_cells, 10u * 10u * 10u);  // depth >= 4
  const StereoLattice fixed = ClassifyLattice(box, 0.4, 6);
  EXPECT_EQ(fixed.pocket_cells, 4u * 4u * 4u);  // depth >= 7
  EXPECT_EQ(fixed.free_cells + fixed.pocket_cells, fixed.hull_cells);
}

// Interior cells of a solved graph over `lattice`: its pockets and free cells on the source side.
std::vector<uint8_t> InteriorOf(const StereoLattice& lattice, const StereoGraph& graph) {
  std::vector<uint8_t> inside(lattice.roles.size(), 0);
  for (size_t c = 0; c < inside.size(); ++c) {
    inside[c] =
        lattice.roles[c] == CellRole::kPocket ||
        (lattice.roles[c] == CellRole::kFree && graph.graph.IsSourceSide(graph.node_of_cell[c]));
  }
  return inside;
}

// What the silhouette step relies on: forcing free cells' nodes to the source and re-solving
// incrementally gives the cut (cost and cells) of the graph rebuilt with them as pockets.
TEST(StereoGraph, ForcingNodesMatchesTheRebuiltGraph) {
  for (int seed = 0; seed < 3; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(seed));
    VoteVolume votes = Lattice(32);
    const Eigen::Vector3d centre(16, 16, 16);
    VoteSphere(votes, centre, 8.3, 0.6, rng);
    const VoxelGrid hull =
        GridOf(votes, [&](const Eigen::Vector3d& p) { return (p - centre).norm() < 13; });
    StereoLattice lattice = ClassifyLattice(hull, 0.4, 0);
    StereoGraph incremental = BuildStereoGraph(lattice, votes, 1.0, 0.05);
    incremental.graph.Solve();
    std::uniform_int_distribution<size_t> cell(0, lattice.roles.size() - 1);
    for (int round = 0; round < 3; ++round) {
      // Free exterior cells, as the silhouette step forces them.
      const std::vector<uint8_t> before = InteriorOf(lattice, incremental);
      for (int forced = 0; forced < 40;) {
        const size_t c = cell(rng);
        if (lattice.roles[c] != CellRole::kFree || before[c] != 0) continue;
        lattice.roles[c] = CellRole::kPocket;
        --lattice.free_cells;
        ++lattice.pocket_cells;
        incremental.graph.ForceSourceSide(incremental.node_of_cell[c]);
        ++forced;
      }
      const double cost = incremental.graph.Resolve() + incremental.forced_cost;
      StereoGraph rebuilt = BuildStereoGraph(lattice, votes, 1.0, 0.05);
      const double expected = rebuilt.graph.Solve() + rebuilt.forced_cost;
      EXPECT_NEAR(cost, expected, 1e-9 * expected) << "seed " << seed << " round " << round;
      EXPECT_TRUE(InteriorOf(lattice, incremental) == InteriorOf(lattice, rebuilt))
          << "seed " << seed << " round " << round;
    }
  }
}

TEST(VolumetricGraphCut, RecoversASphereOfVotesInsideTheHull) {
  for (int seed = 0; seed < 3; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(seed));
    VoteVolume votes = Lattice(40);
    const Eigen::Vector3d centre(20, 20, 20);
    const double r = 10.3, hull_radius = 16;
    VoteSphere(votes, centre, r, 0.85, rng);
    const VoxelGrid hull =
        GridOf(votes, [&](const Eigen::Vector3d& p) { return (p - centre).norm() < hull_radius; });
    const VolumetricGraphCutResult cut = VolumetricGraphCut(votes, hull, {});
    ASSERT_TRUE(cut.success) << cut.reason;
    SCOPED_TRACE(cut.stats.Brief());
    EXPECT_LT(cut.stats.inner_offset_cells, r - 1);
    size_t wrong = 0;
    for (int k = 0; k < 40; ++k)
      for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i) {
          const double d = (CellCentre(i, j, k) - centre).norm();
          const bool interior = cut.interior.IsOccupied(i, j, k);
          if ((d < r - 1 && !interior) || (d > r + 1 && interior)) ++wrong;
        }
    EXPECT_EQ(wrong, 0u);

    const MeshCheck check = CheckClosedManifold(cut.surface);
    EXPECT_TRUE(check.closed_manifold) << check.reason;
    EXPECT_EQ(check.euler_characteristic, 2);
    const Eigen::Vector3d world_centre = votes.origin + kCell * centre;
    double worst = 0;
    for (const auto& v : cut.surface.vertices) {
      const double radius = (v.cast<double>() - world_centre).norm() / kCell;
      worst = std::max(worst, std::abs(radius - r));
    }
    EXPECT_LE(worst, 1.0) << "seed " << seed;
    if (seed == 0) {  // the surface is what the PLY writer stores and reads back
      const testing::TempDir dir;
      WritePlyMesh((dir / "cut.ply").string(), cut.surface);
      const TriangleMesh back = ReadPlyMesh((dir / "cut.ply").string());
      EXPECT_EQ(back.triangles, cut.surface.triangles);
      EXPECT_EQ(back.vertices, cut.surface.vertices);
    }
  }
}

// A cube of cells [8, 40)^3 with a dent x, y in [18, 30), z in [30, 40) opened at the top.
bool InDentedCube(const Eigen::Vector3d& p) {
  const bool cube = (p.array() > 8).all() && (p.array() < 40).all();
  const bool dent = p.x() > 18 && p.x() < 30 && p.y() > 18 && p.y() < 30 && p.z() > 30;
  return cube && !dent;
}

// The dented cube's surface voted in the cells on both sides of it.
VoteVolume DentedCubeVotes() {
  VoteVolume votes = Lattice(48);
  const VoxelGrid solid = GridOf(votes, InDentedCube);
  for (int k = 0; k < 48; ++k)
    for (int j = 0; j < 48; ++j)
      for (int i = 0; i < 48; ++i) {
        const bool in = solid.IsOccupied(i, j, k);
        const bool boundary =
            solid.IsOccupied(i + 1, j, k) != in || solid.IsOccupied(i - 1, j, k) != in ||
            solid.IsOccupied(i, j + 1, k) != in || solid.IsOccupied(i, j - 1, k) != in ||
            solid.IsOccupied(i, j, k + 1) != in || solid.IsOccupied(i, j, k - 1) != in;
        if (boundary) votes.votes[votes.Index(i, j, k)] = 10;
      }
  return votes;
}

TEST(VolumetricGraphCut, RecoversADentTheHullFills) {
  const VoteVolume votes = DentedCubeVotes();
  const VoxelGrid hull = GridOf(votes, [](const Eigen::Vector3d& p) {
    return (p.array() > 5).all() && (p.array() < 43).all();
  });
  VolumetricGraphCutOptions options;
  options.inner_offset_cells = 14;  // the dent's floor lies 13 cells deep
  const VolumetricGraphCutResult cut = VolumetricGraphCut(votes, hull, options);
  ASSERT_TRUE(cut.success) << cut.reason;
  SCOPED_TRACE(cut.stats.Brief());
  // The true surface lies on cell faces with both adjacent cells voted, so cuts one cell
  // either side of it cost the same where it bends (e.g. cutting off a convex edge's cells):
  // only cells more than one cell (in the 26-neighbourhood) from the surface must be right.
  const VoxelGrid truth = GridOf(votes, InDentedCube);
  const auto near_surface = [&](int i, int j, int k) {
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di)
          if (truth.IsOccupied(i + di, j + dj, k + dk) != truth.IsOccupied(i, j, k)) return true;
    return false;
  };
  size_t dent_cells = 0, dent_filled = 0, wrong = 0, wrong_near = 0;
  for (int k = 0; k < 48; ++k)
    for (int j = 0; j < 48; ++j)
      for (int i = 0; i < 48; ++i) {
        const Eigen::Vector3d p = CellCentre(i, j, k);
        const bool interior = cut.interior.IsOccupied(i, j, k);
        if (interior != truth.IsOccupied(i, j, k)) ++(near_surface(i, j, k) ? wrong_near : wrong);
        if (p.x() > 18 && p.x() < 30 && p.y() > 18 && p.y() < 30 && p.z() > 30 && p.z() < 40) {
          ASSERT_TRUE(hull.IsOccupied(i, j, k));
          ++dent_cells;
          dent_filled += interior ? 1 : 0;
        }
      }
  EXPECT_EQ(dent_cells, 12u * 12u * 10u);
  EXPECT_LE(dent_filled, dent_cells / 10);
  EXPECT_EQ(wrong, 0u);
  EXPECT_LE(wrong_near, cut.stats.interior_cells / 50);
  const MeshCheck check = CheckClosedManifold(cut.surface);
  EXPECT_TRUE(check.closed_manifold) << check.reason;
  EXPECT_EQ(check.euler_characteristic, 2);

  // The same hull as a closed box mesh, voxelised on the lattice, gives the same cut.
  TriangleMesh box;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner((c & 1) ? 43 : 5, (c & 2) ? 43 : 5, (c & 4) ? 43 : 5);
    box.vertices.push_back((votes.origin + kCell * corner).cast<float>());
  }
  box.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  ASSERT_TRUE(CheckClosedManifold(box).closed_manifold);
  const VolumetricGraphCutResult from_mesh = VolumetricGraphCut(votes, box, options);
  ASSERT_TRUE(from_mesh.success) << from_mesh.reason;
  EXPECT_EQ(from_mesh.interior.occupied, cut.interior.occupied);
}

TEST(VolumetricGraphCut, BallooningKeepsTheHullWithoutVotes) {
  const VoteVolume votes = Lattice(30);
  const Eigen::Vector3d centre(15, 15, 15);
  const VoxelGrid hull =
      GridOf(votes, [&](const Eigen::Vector3d& p) { return (p - centre).norm() < 12; });
  VolumetricGraphCutOptions options;
  options.extract_surface = false;
  // No votes, no ballooning: the minimal surface hugs the pockets (the minimal-surface bias).
  const VolumetricGraphCutResult shrunk = VolumetricGraphCut(votes, hull, options);
  ASSERT_TRUE(shrunk.success);
  EXPECT_TRUE(shrunk.surface.triangles.empty());
  EXPECT_LT(shrunk.stats.interior_cells, shrunk.stats.pocket_cells * 11 / 10);
  // A reward of 6 per cell outweighs any cell's faces: the whole hull is kept.
  options.ballooning = 6;
  const VolumetricGraphCutResult kept = VolumetricGraphCut(votes, hull, options);
  ASSERT_TRUE(kept.success);
  EXPECT_EQ(kept.interior.occupied, hull.occupied);
}

TEST(VolumetricGraphCut, FailuresAreData) {
  const VoteVolume votes = Lattice(10);
  const VoxelGrid empty = VoxelGrid::Empty(votes.origin, votes.cell_size, votes.dims);
  const VolumetricGraphCutResult none = VolumetricGraphCut(votes, empty, {});
  EXPECT_FALSE(none.success);
  EXPECT_NE(none.reason.find("no cell"), std::string::npos);

  const VoxelGrid slab = GridOf(votes, [](const Eigen::Vector3d& p) { return p.z() < 2; });
  VolumetricGraphCutOptions deep;
  deep.inner_offset_cells = 5;
  const VolumetricGraphCutResult thin = VolumetricGraphCut(votes, slab, deep);
  EXPECT_FALSE(thin.success);
  EXPECT_NE(thin.reason.find("deeper than the inner offset"), std::string::npos);

  // Cancelled: stops after the max-flow, a failure with its reason.
  const VoxelGrid ball = GridOf(
      votes, [](const Eigen::Vector3d& p) { return (p - Eigen::Vector3d(5, 5, 5)).norm() < 4.5; });
  Progress cancelled("cut", 0);
  cancelled.Cancel();
  const VolumetricGraphCutResult stopped = VolumetricGraphCut(votes, ball, {}, nullptr, &cancelled);
  EXPECT_FALSE(stopped.success);
  EXPECT_EQ(stopped.reason, "cancelled");
  EXPECT_TRUE(stopped.surface.triangles.empty());

  const VoxelGrid other = VoxelGrid::Empty(votes.origin, 2 * votes.cell_size, votes.dims);
  EXPECT_THROW(VolumetricGraphCut(votes, other, {}), CheckError);
  VolumetricGraphCutOptions bad;
  bad.lambda = 0;
  std::string reason;
  EXPECT_FALSE(bad.IsValid(&reason));
  EXPECT_EQ(reason, "lambda must be > 0");
  bad = {};
  bad.surface.smoothing_mu = -0.1;
  EXPECT_FALSE(bad.IsValid(&reason));
  EXPECT_THROW(VolumetricGraphCut(votes, slab, bad), CheckError);
}

// Sizes and times on an n^3 lattice: a sphere of votes (radius 0.35 n) in a spherical hull
// (radius 0.47 n). Reported in docs/PERFORMANCE.md; SILNET_GRAPH_CUT_CELLS sets n (128).
TEST(VolumetricGraphCut, LatticeFigures) {
  const char* env = std::getenv("SILNET_GRAPH_CUT_CELLS");
  const int n = env != nullptr ? std::atoi(env) : 128;
  ASSERT_GE(n, 16);
  std::mt19937_64 rng(1);
  VoteVolume votes = Lattice(n);
  const Eigen::Vector3d centre(n / 2.0, n / 2.0, n / 2.0);
  VoteSphere(votes, centre, 0.35 * n, 0.85, rng);
  const VoxelGrid hull =
      GridOf(votes, [&](const Eigen::Vector3d& p) { return (p - centre).norm() < 0.47 * n; });
  const VolumetricGraphCutResult cut = VolumetricGraphCut(votes, hull, {});
  ASSERT_TRUE(cut.success) << cut.reason;
  std::printf("%d^3: %s\n", n, cut.stats.Brief().c_str());
  EXPECT_TRUE(CheckClosedManifold(cut.surface).closed_manifold);
}

// A rod one cell thick shrinks under the smoothing; the corners of its pinned cells stay on
// the lattice, the other vertices still move, and the mesh stays closed.
TEST(ExtractCutSurface, PinnedCellsKeepTheirCorners) {
  VoxelGrid rod = VoxelGrid::Empty(Eigen::Vector3d(0.1, -0.2, 0.3), 0.01, {12, 5, 5});
  for (int i = 1; i < 11; ++i)
    rod.occupied[rod.Index(i, 2, 2)] = 1;
  const std::vector<size_t> pinned = {rod.Index(5, 2, 2)};
  const SurfaceExtractionOptions options;
  const TriangleMesh free = ExtractCutSurface(rod, options);
  const TriangleMesh held = ExtractCutSurface(rod, options, pinned);
  ASSERT_EQ(free.vertices.size(), held.vertices.size());
  EXPECT_TRUE(CheckClosedManifold(held).closed_manifold);
  size_t on_corners = 0, moved = 0;
  for (const Eigen::Vector3f& v : held.vertices) {
    const Eigen::Vector3d lattice = (v.cast<double>() - rod.origin) / rod.voxel_size;
    const bool corner_of_pinned = std::abs(lattice.x() - 5.5) < 0.51 &&
                                  std::abs(lattice.y() - 2.5) < 0.51 &&
                                  std::abs(lattice.z() - 2.5) < 0.51;
    if (corner_of_pinned && (lattice - lattice.array().round().matrix()).norm() < 1e-4)
      ++on_corners;
  }
  for (size_t v = 0; v < free.vertices.size(); ++v) {
    const Eigen::Vector3d lattice = (free.vertices[v].cast<double>() - rod.origin) / rod.voxel_size;
    if ((lattice - lattice.array().round().matrix()).norm() > 0.05) ++moved;
  }
  EXPECT_EQ(on_corners, 8u);
  EXPECT_GT(moved, free.vertices.size() / 2);
}

}  // namespace
}  // namespace silnet::aggregator

#include "aggregator/stereo/adaptive_tet_mesh.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

// The four faces of a tetrahedron, each as three corner positions.
constexpr int kFaces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};

// The cells (ids[4 c .. 4 c + 3] their faces) with a crossing face or, if the options say so,
// a face the hull's surface crosses; the cells are tested in parallel blocks.
std::vector<int32_t> ActiveCells(const std::vector<int32_t>& cells,
                                 const std::vector<std::array<int32_t, 3>>& ids,
                                 const CrossingFaces& crossing,
                                 const AdaptiveTetMeshOptions& options) {
  constexpr size_t kBlock = 4096;
  std::vector<uint8_t> crossed(cells.size(), 0);
  ParallelFor((cells.size() + kBlock - 1) / kBlock, options.threads, [&](size_t block) {
    for (size_t c = block * kBlock; c < std::min(cells.size(), (block + 1) * kBlock); ++c) {
      for (size_t f = 4 * c; f < 4 * c + 4 && crossed[c] == 0; ++f) {
        const FaceSamples counts = crossing.Counts(SortedFace(ids[f][0], ids[f][1], ids[f][2]));
        crossed[c] =
            crossing.Crossing(counts) || (options.refine_hull_surface && counts.OnHullSurface());
      }
    }
  });
  std::vector<int32_t> active;
  for (size_t c = 0; c < cells.size(); ++c)
    if (crossed[c] != 0) active.push_back(cells[c]);
  return active;
}

// The sampled faces of the cells that were refined hand their samples down to their halves.
void HandDownSamples(const RedGreenMesh& mesh, const std::vector<int32_t>& cells,
                     CrossingFaces* crossing) {
  for (int32_t cell : cells) {
    if (mesh.IsLeaf(cell)) continue;
    const Tetrahedron& v = mesh.Corners(cell);
    for (const auto& f : kFaces) {
      const int32_t a = v[f[0]], b = v[f[1]], c = v[f[2]];
      if (!crossing->Known(SortedFace(a, b, c))) continue;
      crossing->Inherit(a, b, c, mesh.Midpoint(a, b), mesh.Midpoint(b, c), mesh.Midpoint(c, a));
    }
  }
}

}  // namespace

void AdaptiveTetMeshOptions::SetFinestSpacing(double footprints) {
  const AdaptiveTetMeshOptions defaults;
  finest_spacing_footprints = footprints;
  if (footprints > 0) {
    base_spacing_footprints =
        footprints * defaults.base_spacing_footprints / defaults.finest_spacing_footprints;
  }
}

bool AdaptiveTetMeshOptions::IsValid(std::string* reason) const {
  const auto fail = [&](const char* why) {
    if (reason) *reason = why;
    return false;
  };
  if (!(base_spacing_footprints > 0)) return fail("base_spacing_footprints must be positive");
  if (!(finest_spacing_footprints > 0 && finest_spacing_footprints <= base_spacing_footprints))
    return fail("finest_spacing_footprints must be positive and at most the base spacing");
  if (!(min_score > -1 && min_score < 1)) return fail("min_score must be in (-1, 1)");
  if (!(crossing_fraction > 0 && crossing_fraction <= 1))
    return fail("crossing_fraction must be in (0, 1]");
  if (crossing_samples < 1) return fail("crossing_samples must be at least 1");
  if (!(sample_spacing_footprints > 0)) return fail("sample_spacing_footprints must be positive");
  if (!(prefilter_margin >= 0)) return fail("prefilter_margin must not be negative");
  if (full_orientations < 1) return fail("full_orientations must be at least 1");
  return patch.IsValid(reason);
}

AdaptiveTetMesh BuildAdaptiveTetMesh(const std::vector<StereoView>& views, const WorldBox& box,
                                     double footprint, const AdaptiveTetMeshOptions& options,
                                     Progress* progress) {
  std::string reason;
  SILNET_CHECK_MSG(options.IsValid(&reason), reason);
  SILNET_CHECK(footprint > 0);
  const double base = options.base_spacing_footprints * footprint;
  const int levels = std::max(
      0,
      static_cast<int>(std::ceil(
          std::log2(options.base_spacing_footprints / options.finest_spacing_footprints) - 1e-9)));
  AdaptiveTetMesh result{RedGreenMesh(BuildBccLattice(box, base)), {}, {}};
  RedGreenMesh& mesh = result.mesh;

  const PatchScorer scorer(views, options.patch);
  CrossingFaceOptions crossing_options;
  crossing_options.sample_spacing = options.sample_spacing_footprints * footprint;
  crossing_options.patch_step = footprint;
  crossing_options.min_score = options.min_score;
  crossing_options.prefilter_margin = options.prefilter_margin;
  crossing_options.full_orientations = options.full_orientations;
  crossing_options.crossing_fraction = options.crossing_fraction;
  crossing_options.crossing_samples = options.crossing_samples;
  crossing_options.threads = options.threads;
  CrossingFaces crossing(scorer, crossing_options);

  std::vector<std::array<int32_t, 3>> ids;
  std::vector<TriangleCorners> corners;
  for (int level = 0; level <= levels; ++level) {
    if (progress && progress->cancelled()) break;
    const auto start = std::chrono::steady_clock::now();
    AdaptiveLevelStats stats;
    stats.level = level;
    stats.spacing = std::ldexp(base, -level);
    std::vector<int32_t> cells;
    for (int32_t leaf : mesh.Leaves())
      if (mesh.Level(leaf) == level) cells.push_back(leaf);
    stats.cells = cells.size();
    if (level == levels) {  // the finest cells are not refined: nothing to decide
      stats.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      result.levels.push_back(stats);
      break;
    }

    ids.clear();
    corners.clear();
    for (int32_t cell : cells) {
      const Tetrahedron& v = mesh.Corners(cell);
      for (const auto& f : kFaces) {
        ids.push_back({v[f[0]], v[f[1]], v[f[2]]});
        corners.push_back(
            {mesh.Vertices()[v[f[0]]], mesh.Vertices()[v[f[1]]], mesh.Vertices()[v[f[2]]]});
      }
    }
    const size_t sampled_before = crossing.SampledFaces();
    const size_t scored_before = crossing.SamplesScored();
    const std::vector<size_t> fresh = crossing.FacesToSample(ids);
    if (progress)
      progress->Restart(
          fmt::format("adaptive mesh level {} ({:.2f} mm)", level, stats.spacing * 1e3),
          fresh.size());
    const auto sampling = std::chrono::steady_clock::now();
    const bool keep_lattices = level + 1 < levels;
    crossing.Sample(ids, corners, fresh, &result.points, progress, keep_lattices);
    stats.seconds_sampling =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sampling).count();
    if (progress && progress->cancelled()) break;
    stats.faces_sampled = crossing.SampledFaces() - sampled_before;
    stats.samples_scored = crossing.SamplesScored() - scored_before;

    const std::vector<int32_t> active = ActiveCells(cells, ids, crossing, options);
    stats.active_cells = active.size();
    stats.refined_cells = mesh.Refine(active);
    if (keep_lattices) HandDownSamples(mesh, cells, &crossing);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    spdlog::info(
        "adaptive mesh level {} ({:.2f} mm): {} cells, {} faces sampled ({} samples), {} active, "
        "{} refined, {:.2f} s ({:.2f} s sampling)",
        level, stats.spacing * 1e3, stats.cells, stats.faces_sampled, stats.samples_scored,
        stats.active_cells, stats.refined_cells, stats.seconds, stats.seconds_sampling);
    result.levels.push_back(stats);
  }
  return result;
}

}  // namespace silnet::aggregator

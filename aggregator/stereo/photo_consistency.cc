#include "aggregator/stereo/photo_consistency.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "aggregator/hulls/mesh_measure.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Votes are summed as integers in units of 1/kVoteScale, so the sum is exact and independent
// of the order of the additions.
constexpr double kVoteScale = 256.0;

// Grows the occupied cells of `grid` by `radius` cells along each axis (a cube).
void Dilate(int radius, VoxelGrid* grid) {
  for (int axis = 0; axis < 3 && radius > 0; ++axis) {
    const std::vector<uint8_t> source = grid->occupied;
    const int n = grid->dims[static_cast<size_t>(axis)];
    for (int k = 0; k < grid->dims[2]; ++k) {
      for (int j = 0; j < grid->dims[1]; ++j) {
        for (int i = 0; i < grid->dims[0]; ++i) {
          const size_t index = grid->Index(i, j, k);
          if (source[index] == 0) continue;
          std::array<int, 3> c = {i, j, k};
          const int at = c[static_cast<size_t>(axis)];
          for (int o = std::max(0, at - radius); o <= std::min(n - 1, at + radius); ++o) {
            c[static_cast<size_t>(axis)] = o;
            grid->occupied[grid->Index(c[0], c[1], c[2])] = 1;
          }
        }
      }
    }
  }
}

// Depth intervals [near, far] where the ray centre + d * direction (d > 0) is in a cell of the
// grown hull, found by stepping half a cell at a time.
void HullIntervals(const VoteVolume& volume, const std::vector<uint8_t>& in_hull,
                   const Eigen::Vector3d& centre, const Eigen::Vector3d& direction,
                   std::vector<std::pair<double, double>>* intervals) {
  intervals->clear();
  // Slab intersection with the lattice's box.
  const Eigen::Vector3d lo = volume.origin;
  const Eigen::Vector3d hi =
      volume.origin +
      volume.cell_size * Eigen::Vector3d(volume.dims[0], volume.dims[1], volume.dims[2]);
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(direction[a]) < 1e-15) {
      if (centre[a] < lo[a] || centre[a] > hi[a]) return;
      continue;
    }
    double ta = (lo[a] - centre[a]) / direction[a], tb = (hi[a] - centre[a]) / direction[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t1 > t0)) return;
  const double step = 0.5 * volume.cell_size / direction.norm();
  bool inside = false;
  double start = 0.0;
  for (double d = t0 + 0.5 * step; d < t1; d += step) {
    const Eigen::Vector3d u = (centre + d * direction - volume.origin) / volume.cell_size;
    const int i = static_cast<int>(std::floor(u.x())), j = static_cast<int>(std::floor(u.y())),
              k = static_cast<int>(std::floor(u.z()));
    const bool in = volume.InGrid(i, j, k) && in_hull[volume.Index(i, j, k)] != 0;
    if (in && !inside) start = d - 0.5 * step;
    if (!in && inside) intervals->emplace_back(start, d - 0.5 * step);
    inside = in;
  }
  if (inside) intervals->emplace_back(start, t1);
}

// What one thread accumulates.
struct ThreadState {
  std::vector<uint32_t> votes;  // fixed point, per cell
  PhotoConsistencyStats stats;
  std::vector<float> window;
  std::vector<float> scores;
  std::vector<EpipolarMatch> matches;
  std::vector<std::pair<double, double>> intervals;
};

// A band of reference rows of one view.
struct WorkItem {
  int view = 0;
  int row_begin = 0;
  int row_end = 0;
};

}  // namespace

std::string PhotoConsistencyOptions::Validate() const {
  if (std::string reason = neighbours.Validate(); !reason.empty()) return reason;
  if (std::string reason = matching.Validate(); !reason.empty()) return reason;
  if (pixel_step < 1) return "pixel_step must be at least 1";
  if (!(cell_size >= 0.0)) return "cell_size must not be negative (0 = from the footprint)";
  if (cell_size == 0.0 && !(cell_size_footprints > 0.0))
    return "cell_size_footprints must be positive";
  if (hull_margin_cells < 0) return "hull_margin_cells must not be negative";
  if (rows_per_item < 1) return "rows_per_item must be at least 1";
  if (threads < 0) return "threads must not be negative (0 = all cores)";
  return {};
}

std::string PhotoConsistencyStats::BriefReport() const {
  return fmt::format(
      "{} pixels ({} untextured), {} searches, {} samples, {} matches, {} votes in hull ({} "
      "outside), cell {:.2f} mm; prepare {:.2f} s, matching {:.2f} s, merge {:.2f} s",
      reference_pixels, untextured_pixels, searches, samples, matches, votes_in_hull,
      votes_outside_hull, cell_size * 1e3, seconds_prepare, seconds_matching, seconds_merge);
}

double MeanFootprint(const std::vector<StereoView>& views, const TriangleMesh& mesh) {
  if (mesh.vertices.empty() || views.empty()) return 0.0;
  WorldBox box;
  for (const Eigen::Vector3f& v : mesh.vertices)
    box.extend(v.cast<double>());
  double footprint = 0.0;
  for (const StereoView& view : views) {
    const double depth = (view.camera.R * box.center() + view.camera.t).z();
    footprint += std::abs(depth) / view.camera.K(0, 0);
  }
  return footprint / static_cast<double>(views.size());
}

PhotoConsistencyResult ComputePhotoConsistency(const std::vector<StereoView>& views,
                                               const TriangleMesh& hull,
                                               const PhotoConsistencyOptions& options,
                                               Progress* progress) {
  if (std::string reason = options.Validate(); !reason.empty())
    throw InputError("photo-consistency: " + reason);
  PhotoConsistencyResult result;
  const auto fail = [&](std::string reason) {
    result.success = false;
    result.reason = std::move(reason);
    return result;
  };
  if (views.size() < 2) return fail("photo-consistency needs at least two views");
  for (const StereoView& view : views) {
    if (view.camera.HasDistortion())
      return fail(fmt::format("view {} is not pinhole (undistort it first)", view.camera.id));
    SILNET_CHECK(view.image.cols == view.camera.width && view.image.rows == view.camera.height);
  }
  if (hull.triangles.empty()) return fail("the visual hull is empty");

  // Prepare: the hull's box and the mean footprint there, the lattice, the hull in it.
  const Clock::time_point prepare_start = Clock::now();
  WorldBox box;
  for (const Eigen::Vector3f& v : hull.vertices)
    box.extend(v.cast<double>());
  const Eigen::Vector3d object_centre = box.center();
  const double footprint = MeanFootprint(views, hull);
  const double cell =
      options.cell_size > 0.0 ? options.cell_size : options.cell_size_footprints * footprint;
  const double pad = (options.hull_margin_cells + 1) * cell;
  box.min() -= Eigen::Vector3d::Constant(pad);
  box.max() += Eigen::Vector3d::Constant(pad);
  result.volume = VoteVolume::Covering(box, cell);
  VoxelGrid geometry;
  geometry.origin = result.volume.origin;
  geometry.voxel_size = result.volume.cell_size;
  geometry.dims = result.volume.dims;
  VoxelGrid inside = RasterizeMesh(hull, geometry);
  Dilate(options.hull_margin_cells, &inside);
  result.in_hull = std::move(inside.occupied);

  std::vector<CameraModel> cameras;
  for (const StereoView& view : views)
    cameras.push_back(view.camera);
  result.neighbours = SelectNeighbourViews(cameras, object_centre, options.neighbours);
  for (size_t v = 0; v < views.size(); ++v) {
    if (result.neighbours[v].empty())
      result.warnings.push_back(fmt::format("{}: no neighbour view within {}-{} degrees",
                                            views[v].camera.id, options.neighbours.min_angle_deg,
                                            options.neighbours.max_angle_deg));
  }
  std::vector<NccImage> images(views.size());
  const int threads = ResolveThreadCount(options.threads, views.size());
  ParallelFor(views.size(), threads,
              [&](size_t v) { images[v] = NccImage::FromView(views[v], options.matching.colour); });

  // Work items: bands of rows holding silhouette pixels of views with neighbours.
  std::vector<WorkItem> items;
  for (size_t v = 0; v < views.size(); ++v) {
    if (result.neighbours[v].empty()) continue;
    const cv::Rect bounds = cv::boundingRect(views[v].mask);
    for (int y = bounds.y; y < bounds.y + bounds.height; y += options.rows_per_item)
      items.push_back(
          {static_cast<int>(v), y, std::min(bounds.y + bounds.height, y + options.rows_per_item)});
  }
  result.stats.cell_size = cell;
  result.stats.footprint = footprint;
  result.stats.seconds_prepare = SecondsSince(prepare_start);

  // Matching and voting.
  const Clock::time_point matching_start = Clock::now();
  if (progress) progress->Restart("photo-consistency", items.size());
  const int workers = ResolveThreadCount(options.threads, items.size());
  std::vector<ThreadState> states(static_cast<size_t>(workers));
  std::atomic<size_t> next{0};
  const VoteVolume& volume = result.volume;
  const std::vector<uint8_t>& in_hull = result.in_hull;
  const auto process = [&](const WorkItem& item, ThreadState& state) {
    const StereoView& view = views[static_cast<size_t>(item.view)];
    const NccImage& reference = images[static_cast<size_t>(item.view)];
    const CameraModel& camera = view.camera;
    const Eigen::Vector3d centre = camera.Center();
    const Eigen::Matrix3d back = camera.R.transpose() * camera.K.inverse();
    const std::vector<int>& neighbours = result.neighbours[static_cast<size_t>(item.view)];
    const int step = options.pixel_step;
    const int first_row = (item.row_begin + step - 1) / step * step;
    for (int y = first_row; y < item.row_end; y += step) {
      const uint8_t* mask_row = view.mask.ptr<uint8_t>(y);
      for (int x = 0; x < view.mask.cols; x += step) {
        if (mask_row[x] == 0) continue;
        ++state.stats.reference_pixels;
        if (!ReferenceWindow(reference, x, y, options.matching, &state.window)) {
          ++state.stats.untextured_pixels;
          continue;
        }
        const Eigen::Vector3d direction = back * Eigen::Vector3d(x, y, 1.0);
        HullIntervals(volume, in_hull, centre, direction, &state.intervals);
        if (state.intervals.empty()) continue;
        for (size_t n = 0; n < neighbours.size(); ++n) {
          const EpipolarRay ray =
              EpipolarRay::Of(views[static_cast<size_t>(neighbours[n])].camera, centre, direction);
          ++state.stats.searches;
          state.matches.clear();
          EpipolarScanCounts counts;
          for (const auto& [near, far] : state.intervals)
            ScanEpipolarSegment(images[static_cast<size_t>(neighbours[n])], state.window.data(),
                                ray, near, far, options.matching, &state.scores, &state.matches,
                                &counts);
          KeepBestMatches(options.matching.max_matches, 0, &state.matches);
          state.stats.samples += counts.samples;
          state.stats.scored_samples += counts.scored;
          state.stats.matches += state.matches.size();
          for (const EpipolarMatch& match : state.matches) {
            const auto ijk = volume.CellOf(centre + match.depth * direction);
            const size_t index = ijk ? volume.Index((*ijk)[0], (*ijk)[1], (*ijk)[2]) : 0;
            if (!ijk || in_hull[index] == 0) {
              ++state.stats.votes_outside_hull;
              continue;
            }
            ++state.stats.votes_in_hull;
            const double weight = options.weight_by_ncc ? std::max(0.0f, match.ncc) : 1.0;
            state.votes[index] += static_cast<uint32_t>(std::lround(weight * kVoteScale));
          }
        }
      }
    }
  };
  std::atomic<bool> cancelled{false};
  ParallelFor(states.size(), workers, [&](size_t t) {
    ThreadState& state = states[t];
    state.votes.assign(volume.size(), 0u);
    for (size_t i = next.fetch_add(1); i < items.size(); i = next.fetch_add(1)) {
      if (progress && progress->cancelled()) {
        cancelled.store(true);
        return;
      }
      process(items[i], state);
      if (progress) progress->Advance();
    }
  });
  result.stats.seconds_matching = SecondsSince(matching_start);
  if (cancelled.load()) return fail("cancelled");

  // Merge the threads' votes and counts.
  const Clock::time_point merge_start = Clock::now();
  PhotoConsistencyStats& total = result.stats;
  for (const ThreadState& state : states) {
    total.reference_pixels += state.stats.reference_pixels;
    total.untextured_pixels += state.stats.untextured_pixels;
    total.searches += state.stats.searches;
    total.samples += state.stats.samples;
    total.scored_samples += state.stats.scored_samples;
    total.matches += state.stats.matches;
    total.votes_in_hull += state.stats.votes_in_hull;
    total.votes_outside_hull += state.stats.votes_outside_hull;
  }
  std::vector<float>& votes = result.volume.votes;
  const size_t cells = votes.size();
  const size_t chunk = 1u << 16;
  ParallelFor((cells + chunk - 1) / chunk, workers, [&](size_t c) {
    const size_t end = std::min(cells, (c + 1) * chunk);
    for (size_t i = c * chunk; i < end; ++i) {
      uint64_t sum = 0;
      for (const ThreadState& state : states)
        sum += state.votes[i];
      votes[i] = static_cast<float>(static_cast<double>(sum) / kVoteScale);
    }
  });
  total.seconds_merge = SecondsSince(merge_start);
  if (progress) progress->Finish();
  result.success = true;
  return result;
}

}  // namespace silnet::aggregator

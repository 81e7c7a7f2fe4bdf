#include "aggregator/calibration/moved_camera_reestimation.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <numbers>

#include "aggregator/calibration/epipolar_consistency.h"
#include "aggregator/calibration/relative_pose.h"
#include "aggregator/calibration/two_view_tracks.h"
#include "aggregator/calibration/view_graph.h"
#include "shared/geometry/epipolar.h"
#include "shared/util/check.h"
#include "shared/util/parallel_for.h"

namespace silnet::aggregator {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// The moved camera against each calibrated partner that has a sequence; pairs keep the
// cameras' order (lower index first).
std::vector<PairwiseResult> EstimatePartnerPairs(const std::vector<CameraModel>& cameras,
                                                 const std::vector<bool>& placed, size_t moved,
                                                 const std::vector<SilhouetteSequence>& sequences,
                                                 const MovedCameraOptions& options,
                                                 Progress* progress) {
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t p = 0; p < cameras.size(); ++p) {
    if (p == moved || !placed[p] || FindSequence(sequences, cameras[p].id) == nullptr) continue;
    pairs.emplace_back(std::min(p, moved), std::max(p, moved));
  }
  if (progress) progress->Restart("re-estimating " + cameras[moved].id, pairs.size());
  std::vector<PairwiseResult> results(pairs.size());
  ParallelFor(pairs.size(), options.threads, [&](size_t k) {
    if (progress != nullptr && progress->cancelled()) return;
    const auto [a, b] = pairs[k];
    PairwiseOptions pair = options.pair;
    pair.seed = options.pair.seed * 1000003u + k;
    pair.offset_prior = PairTimingFromCameras(cameras[a], cameras[b]).offset;
    pair.prior_sigma = options.offset_prior_sigma;
    results[k] = EstimatePair(*FindSequence(sequences, cameras[a].id),
                              *FindSequence(sequences, cameras[b].id), pair);
    const PairwiseResult& r = results[k];
    spdlog::info("moved camera {}: pair {}-{}: {}{}{} ({} inliers)", cameras[moved].id, r.camera_i,
                 r.camera_j, ToString(r.status), r.reason.empty() ? "" : ": ", r.reason, r.inliers);
    if (progress != nullptr) progress->Advance();
  });
  return results;
}

// Angle between the ray origin + s direction and the direction from origin to `centre`.
double RayMiss(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
               const Eigen::Vector3d& centre) {
  const double c = std::clamp(direction.dot((centre - origin).normalized()), -1.0, 1.0);
  return std::acos(c);
}

}  // namespace

MovedCameraEstimate ReestimateMovedCamera(const std::vector<CameraModel>& cameras,
                                          const std::vector<bool>& placed, size_t moved,
                                          const std::vector<SilhouetteSequence>& sequences,
                                          const MovedCameraOptions& options, Progress* progress) {
  SILNET_CHECK(placed.size() == cameras.size() && moved < cameras.size());
  const auto start = std::chrono::steady_clock::now();
  MovedCameraEstimate out;
  out.camera = cameras[moved];
  const auto finish = [&](std::string reason) {
    out.reason = std::move(reason);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!out.ok)
      spdlog::warn("moved camera {}: not re-estimated: {}", cameras[moved].id, out.reason);
    return out;
  };
  if (FindSequence(sequences, cameras[moved].id) == nullptr)
    return finish("no frames of the camera after the move");
  out.pairs = EstimatePartnerPairs(cameras, placed, moved, sequences, options, progress);
  if (progress != nullptr && progress->cancelled()) return finish("cancelled");

  std::vector<std::string> ids;
  for (const CameraModel& c : cameras)
    ids.push_back(c.id);
  const ViewGraph graph = BuildViewGraph(ids, out.pairs);
  struct Partner {
    size_t camera;
    Eigen::Matrix3d rotation;  // of the moved camera, as this partner implies it
    Eigen::Vector3d origin, direction;
  };
  std::vector<Partner> partners;
  for (size_t p : graph.Neighbours(moved)) {
    const auto pose = PoseOfLink(graph, cameras, p, moved);
    if (!pose) continue;
    partners.push_back(
        {p, pose->R * cameras[p].R, cameras[p].Center(), RayTowards(cameras[p], *pose)});
  }
  if (partners.size() < options.min_pairs) {
    return finish(fmt::format(
        "only {} of {} pairs with the other cameras gave a relative pose ({} needed): too "
        "little motion seen since the move?",
        partners.size(), out.pairs.size(), options.min_pairs));
  }
  // The centre nearest to the partners' rays, dropping the worst-fitting ray while it misses
  // by more than max_ray_miss_deg and enough partners remain.
  Eigen::Vector3d centre;
  while (true) {
    std::vector<Eigen::Vector3d> origins, directions;
    for (const Partner& p : partners) {
      origins.push_back(p.origin);
      directions.push_back(p.direction);
    }
    centre = NearestToRays(origins, directions);
    size_t worst = 0;
    for (size_t k = 1; k < partners.size(); ++k) {
      if (RayMiss(partners[k].origin, partners[k].direction, centre) >
          RayMiss(partners[worst].origin, partners[worst].direction, centre))
        worst = k;
    }
    const double miss = RayMiss(partners[worst].origin, partners[worst].direction, centre);
    if (miss <= options.max_ray_miss_deg * kDegree || partners.size() <= options.min_pairs) break;
    spdlog::info("moved camera {}: {}'s ray misses the others by {:.1f} deg; left out",
                 cameras[moved].id, cameras[partners[worst].camera].id, miss / kDegree);
    partners.erase(partners.begin() + static_cast<std::ptrdiff_t>(worst));
  }
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<bool> selected(cameras.size(), false);
  selected[moved] = true;
  for (const Partner& p : partners) {
    rotations.push_back(p.rotation);
    selected[p.camera] = true;
    out.partners.push_back(cameras[p.camera].id);
  }

  MetricScene scene;
  scene.cameras = cameras;
  scene.present = selected;
  scene.held = selected;
  scene.held[moved] = false;
  CameraModel& camera = scene.cameras[moved];
  camera.R = ChordalMean(rotations);
  camera.t = -camera.R * centre;
  scene.tracks = CollectTracks(graph, selected, options.tracks_per_link);
  scene.Triangulate();
  IntrinsicsModel intrinsics;
  intrinsics.fixed = true;
  const BundleSummary bundle = AdjustEuclidean(&scene, intrinsics, options.bundle);
  out.rms_px = bundle.rms_px;
  out.observations = bundle.observations;
  if (!bundle.usable) return finish("the bundle adjustment of its pose failed");
  if (!(bundle.rms_px <= options.max_rms_px)) {
    return finish(
        fmt::format("its new pose fits the frontier points with {:.2f} px rms (at most "
                    "{:.2f} px accepted)",
                    bundle.rms_px, options.max_rms_px));
  }
  out.camera = scene.cameras[moved];
  out.ok = true;
  spdlog::info("moved camera {}: re-estimated from {} partners, {:.3f} px rms over {} observations",
               cameras[moved].id, partners.size(), out.rms_px, out.observations);
  return finish("");
}

}  // namespace silnet::aggregator

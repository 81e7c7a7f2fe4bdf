#include "aggregator/calibration/network_calibration.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <map>
#include <numbers>
#include <optional>

#include "aggregator/calibration/addition_order.h"
#include "aggregator/calibration/ambiguity_resolution.h"
#include "aggregator/calibration/calibration_gates.h"
#include "aggregator/calibration/camera_uncertainty.h"
#include "aggregator/calibration/epipolar_consistency.h"
#include "aggregator/calibration/focal_search.h"
#include "aggregator/calibration/frontier_rematching.h"
#include "aggregator/calibration/global_start.h"
#include "aggregator/calibration/metric_scene_setup.h"
#include "aggregator/calibration/pair_checks.h"
#include "aggregator/calibration/self_calibration.h"
#include "shared/geometry/epipolar.h"
#include "shared/util/check.h"
#include "shared/util/log.h"
#include "shared/util/parallel_for.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::vector<OffsetEdge> OffsetEdges(const std::vector<CameraModel>& cameras,
                                    const std::vector<PairwiseResult>& pairs) {
  std::vector<OffsetEdge> edges;
  for (const PairwiseResult& p : pairs) {
    const size_t i = CameraIndex(cameras, p.camera_i), j = CameraIndex(cameras, p.camera_j);
    if (p.status != PairStatus::kOk || i >= cameras.size() || j >= cameras.size() || i == j)
      continue;
    edges.push_back({i, j, p.offset, std::max(p.offset_sigma, 1e-3)});
  }
  return edges;
}

// Inlier spread score of correspondences (thesis 3.2.3).
double SpreadScore(const std::vector<Correspondence>& matches) {
  if (matches.empty()) return 0.0;
  Eigen::Vector2d mean_i = Eigen::Vector2d::Zero(), mean_j = Eigen::Vector2d::Zero();
  for (const Correspondence& c : matches) {
    mean_i += c.x_i;
    mean_j += c.x_j;
  }
  mean_i /= static_cast<double>(matches.size());
  mean_j /= static_cast<double>(matches.size());
  double s = 0.0;
  for (const Correspondence& c : matches)
    s += (c.x_i - mean_i).squaredNorm() + (c.x_j - mean_j).squaredNorm();
  return s;
}

// The stages after the network has a metric starting point.
class MetricRefinement {
 public:
  MetricRefinement(const CalibrationOptions& options, NetworkCalibration* out)
      : options_(options), out_(out) {}

  // Whether the adjustments that follow keep the principal points as they are.
  void HoldPrincipalPoints(bool hold) { options_.intrinsics.fix_principal_point = hold; }

  // The radial terms the adjustments estimate (the options' or, once detected, k1 and k2).
  int RadialTerms() const { return options_.intrinsics.radial_terms; }

  // Whether the adjustments that follow estimate k1 alone where k1 and k2 are asked for (a
  // rough start can trade a wrong focal length against k1 and k2 together).
  void HoldSecondRadialTerm(bool hold) { hold_k2_ = hold; }

  // Euclidean bundle adjustment on `graph`'s correspondences: first on a sample (the
  // cameras may still be far off), then on at most final_tracks_per_link of each link.
  // Returns the last adjustment's rms reprojection error (px).
  double Adjust(const ViewGraph& graph, MetricScene* scene, const std::string& stage) {
    AdjustOn(graph, scene, stage + " (sample)", options_.projective.tracks_per_link);
    AdjustOn(graph, scene, stage, options_.final_tracks_per_link);
    return last_rms_px_;
  }

 private:
  // One adjustment on at most `per_link` correspondences of each link; radial terms only
  // once the cameras have settled without them.
  void AdjustOn(const ViewGraph& graph, MetricScene* scene, const std::string& stage,
                size_t per_link) {
    scene->tracks = CollectTracks(graph, scene->present, per_link);
    scene->Triangulate();
    IntrinsicsModel model = options_.intrinsics;
    model.fixed = options_.known_intrinsics;
    if (!model.fixed && !distortion_started_ &&
        (model.radial_terms > 0 || options_.detect_distortion)) {
      StartDistortion(scene, model, stage);
      return;
    }
    model.radial_terms = Held(model.radial_terms);
    Record(stage, AdjustEuclidean(scene, model, options_.bundle), "");
  }

  // An adjustment of `scene` without radial terms, then one of a copy of its result (every
  // track an inlier again) with `model`'s radial terms.
  struct RadialFits {
    BundleSummary plain;
    MetricScene radial_scene;
    BundleSummary radial;
  };
  RadialFits FitWithoutAndWithRadialTerms(MetricScene* scene, IntrinsicsModel model) const {
    const int terms = model.radial_terms;
    model.radial_terms = 0;
    RadialFits fits;
    fits.plain = AdjustEuclidean(scene, model, options_.bundle);
    fits.radial_scene = *scene;
    fits.radial_scene.inlier.assign(fits.radial_scene.tracks.size(), true);
    model.radial_terms = terms;
    fits.radial = AdjustEuclidean(&fits.radial_scene, model, options_.bundle);
    return fits;
  }

  // The first adjustment without radial terms, then from its result with the terms asked for
  // or, when they are to be detected, with k1 and k2, kept (and estimated from then on) only if
  // they fit clearly better. With the principal points held at the image centres (after a
  // focal length search) principal points off centre can pass for radial distortion: the
  // detection then compares the same two fits with the principal points free, while the
  // adopted ones keep them held.
  void StartDistortion(MetricScene* scene, IntrinsicsModel model, const std::string& stage) {
    distortion_started_ = true;
    const int asked = model.radial_terms;
    const int terms = asked > 0 ? asked : 2;
    model.radial_terms = Held(terms);
    RadialFits fits = FitWithoutAndWithRadialTerms(scene, model);
    Record(stage, fits.plain, "without distortion");
    if (asked == 0) {
      double plain_rms = fits.plain.rms_px, radial_rms = fits.radial.rms_px;
      if (model.fix_principal_point) {
        IntrinsicsModel free = model;
        free.fix_principal_point = false;
        MetricScene free_scene = *scene;
        const RadialFits free_fits = FitWithoutAndWithRadialTerms(&free_scene, free);
        plain_rms = free_fits.plain.rms_px;
        radial_rms = free_fits.radial.rms_px;
      }
      const bool detected = radial_rms < (1.0 - options_.distortion_gain) * plain_rms;
      const std::string verdict = fmt::format(
          "{}: {} fit the frontier points to {:.3f} px rms against {:.3f} px without{}",
          detected ? "detected" : "not detected", model.radial_terms > 1 ? "k1, k2" : "k1",
          radial_rms, plain_rms, model.fix_principal_point ? " (principal points free)" : "");
      spdlog::info("radial distortion {}", verdict);
      out_->stages.push_back(
          {"radial distortion", fits.radial.rms_px, fits.radial.seconds, verdict});
      if (!detected) return;
      options_.intrinsics.radial_terms = terms;
    }
    *scene = std::move(fits.radial_scene);
    Record(stage + " with radial distortion", fits.radial,
           fmt::format("k1{}", model.radial_terms > 1 ? ", k2" : ""));
  }

  // `radial_terms`, or at most k1 while the second term is held.
  int Held(int radial_terms) const { return hold_k2_ ? std::min(radial_terms, 1) : radial_terms; }

  void Record(const std::string& name, const BundleSummary& s, const std::string& detail) {
    last_rms_px_ = s.rms_px;
    out_->stages.push_back(
        {name, s.rms_px, s.seconds,
         fmt::format("{} observations, median {:.3f} px, {} iterations{}{}", s.observations,
                     s.median_px, s.iterations, detail.empty() ? "" : "; ", detail)});
    spdlog::info("{}: rms {:.3f} px, median {:.3f} px over {} observations ({:.1f} s)", name,
                 s.rms_px, s.median_px, s.observations, s.seconds);
  }
  CalibrationOptions options_;
  NetworkCalibration* out_;
  bool distortion_started_ = false;
  bool hold_k2_ = false;
  double last_rms_px_ = 0.0;
};

// The view graph of every calibrated pair, matched afresh under the calibration.
ViewGraph RematchedGraph(const MetricScene& scene,
                         const std::vector<SilhouetteSequence>& undistorted,
                         const SyncResult& sync) {
  const size_t n = scene.cameras.size();
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (scene.present[i] && scene.present[j] && !undistorted[i].frames.empty() &&
          !undistorted[j].frames.empty())
        pairs.emplace_back(i, j);
    }
  }
  std::vector<ViewLink> links(pairs.size());
  ParallelFor(pairs.size(), 0, [&](size_t p) {
    const auto [i, j] = pairs[p];
    ViewLink& link = links[p];
    link.i = i;
    link.j = j;
    link.F = FundamentalFromCameras(scene.cameras[i], scene.cameras[j]);
    link.matches = RematchFrontierPoints(undistorted[i], undistorted[j], scene.cameras[i],
                                         scene.cameras[j], sync.offsets[i] - sync.offsets[j]);
    link.spread = SpreadScore(link.matches);
  });
  ViewGraph graph(n);
  for (ViewLink& link : links) {
    if (!link.matches.empty()) graph.Add(std::move(link));
  }
  return graph;
}

// The largest angle, degrees, by which a camera present in `scene` turned from `before`.
double LargestRotationChange(const std::vector<CameraModel>& before, const MetricScene& scene) {
  double largest = 0.0;
  for (size_t c = 0; c < before.size(); ++c) {
    if (!scene.present[c]) continue;
    const Eigen::AngleAxisd turn(before[c].R.transpose() * scene.cameras[c].R);
    largest = std::max(largest, turn.angle() * 180.0 / std::numbers::pi);
  }
  return largest;
}

// Makes each pair's candidate that agreed with the global start its solution; usable pairs
// that disagree are no longer trusted.
void ApplyGlobalChoice(const GlobalStart& global, std::vector<PairwiseResult>* pairs) {
  for (size_t p = 0; p < pairs->size(); ++p) {
    PairwiseResult& pair = (*pairs)[p];
    if (pair.status != PairStatus::kOk && pair.status != PairStatus::kAmbiguous) continue;
    const int c = global.candidate[p];
    if (c < 0) {
      pair.status = PairStatus::kDegenerate;
      pair.reason = "its relative pose disagrees with the network's rotations and baselines";
      continue;
    }
    const std::string why = fmt::format(
        "agrees with the network's rotations to {:.2f} deg{}", global.rotation_error_deg[p],
        pair.status == PairStatus::kAmbiguous
            ? fmt::format(" (candidate {} of {})", c + 1, pair.alternatives.size() + 1)
            : "");
    if (c == 0) {
      pair.status = PairStatus::kOk;
      pair.reason = pair.reason.empty() ? "" : why;
    } else {
      pair.Choose(static_cast<size_t>(c - 1), why);
    }
  }
}

// The metric scene of a global start, adjusted with the intrinsics held.
PoseChain SceneFromGlobalStart(const GlobalStart& global, const ViewGraph& graph,
                               const std::vector<CameraModel>& cameras,
                               const KnownIntrinsicsOptions& options) {
  PoseChain chain;
  MetricScene& s = chain.scene;
  s.present = global.present;
  s.cameras = cameras;
  chain.added_by.assign(cameras.size(), "");
  chain.reasons.assign(cameras.size(), "");
  for (size_t c = 0; c < cameras.size(); ++c) {
    if (!s.present[c]) {
      chain.reasons[c] = graph.Neighbours(c).size() < 2
                             ? ReasonNotPlaced(graph, s.present, c)
                             : "fewer than two of its pairs agree with the network's rotations";
      continue;
    }
    s.cameras[c].R = global.R[c];
    s.cameras[c].t = -global.R[c] * global.C[c];
    chain.added_by[c] = "rotation averaging";
  }
  s.tracks = CollectTracks(graph, s.present, options.tracks_per_link);
  s.Triangulate();
  IntrinsicsModel fixed;
  fixed.fixed = true;
  chain.last_bundle = AdjustEuclidean(&s, fixed, options.bundle, options.max_added_rms_px);
  return chain;
}

// Cameras whose silhouettes did not move enough are not calibrated, whatever the fit says.
void RejectCamerasWithoutMotion(NetworkCalibration* out) {
  for (size_t c = 0; c < out->motion.size(); ++c) {
    const MotionCoverage& m = out->motion[c];
    if (m.sufficient || m.frames == 0 || !out->placement[c].placed) continue;
    spdlog::warn("{} is not calibrated: {}", out->cameras[c].id, m.advice);
    out->placement[c].placed = false;
    out->placement[c].reason = m.advice;
  }
}

// Per-camera errors, frontier points and the calibrated cameras, from the final scene.
void FillResult(const MetricScene& scene, const SyncResult& sync, NetworkCalibration* out) {
  const size_t n = scene.cameras.size();
  std::vector<std::vector<double>> errors(n);
  std::vector<double> all;
  out->points.clear();
  for (size_t k = 0; k < scene.tracks.size(); ++k) {
    const TwoViewTrack& t = scene.tracks[k];
    FrontierPoint point;
    point.X = scene.points[k];
    point.frame = t.frame;
    point.inlier = scene.inlier[k];
    for (int view = 0; view < 2; ++view) {
      FrontierObservation& o = point.views[view];
      o.camera = view == 0 ? t.camera_a : t.camera_b;
      o.pixel = view == 0 ? t.x_a : t.x_b;
      o.error_px = scene.ViewError(k, view);
      if (point.inlier) {
        errors[o.camera].push_back(o.error_px);
        all.push_back(o.error_px);
      }
    }
    out->points.push_back(point);
  }
  const auto rms = [](const std::vector<double>& e) {
    double s = 0.0;
    for (double x : e)
      s += x * x;
    return e.empty() ? 0.0 : std::sqrt(s / static_cast<double>(e.size()));
  };
  for (size_t c = 0; c < n; ++c) {
    if (!scene.present[c]) continue;
    CameraModel& camera = out->cameras[c];
    const CameraModel& fitted = scene.cameras[c];
    camera.K = fitted.K;
    camera.dist = fitted.dist;
    camera.R = fitted.R;
    camera.t = fitted.t;
    camera.time_offset = sync.synchronised[c] ? sync.offsets[c] : 0.0;
    CameraPlacement& p = out->placement[c];
    p.placed = true;
    p.observations = errors[c].size();
    p.rms_px = rms(errors[c]);
    p.median_px = UpperMedian(errors[c]);
  }
  out->rms_px = rms(all);
  out->median_px = UpperMedian(all);
}

// Every calibrated camera's uncertainty from the final adjustment, logged and recorded.
// Empty if every present camera's principal point, estimated with `model`'s other settings
// at `scene`'s solution, has a standard deviation within `max_sigma_px`; otherwise why not.
std::string FreePrincipalPoints(const MetricScene& scene, const IntrinsicsModel& model,
                                const BundleOptions& bundle, double max_sigma_px) {
  const std::vector<CameraUncertainty> uncertainty =
      EstimateCameraUncertainty(scene, model, bundle);
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    if (!scene.present[c]) continue;
    if (!uncertainty[c].estimated)
      return fmt::format("held at the image centres ({}: uncertainty not estimated)",
                         scene.cameras[c].id);
    if (uncertainty[c].principal_px > max_sigma_px) {
      return fmt::format(
          "held at the image centres: the frontier points leave {}'s uncertain by {:.1f} px "
          "(free above {:.1f} px)",
          scene.cameras[c].id, uncertainty[c].principal_px, max_sigma_px);
    }
  }
  return "";
}

void AddUncertainty(const MetricScene& scene, const IntrinsicsModel& model,
                    const BundleOptions& bundle, const UncertaintyOptions& options,
                    NetworkCalibration* out) {
  const auto start = Clock::now();
  const std::vector<CameraUncertainty> uncertainty =
      EstimateCameraUncertainty(scene, model, bundle, options);
  std::vector<double> rotations;
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    if (!scene.present[c]) continue;
    const CameraUncertainty& u = uncertainty[c];
    out->placement[c].uncertainty = u;
    if (!u.estimated) {
      spdlog::info("{}: uncertainty not estimated", out->cameras[c].id);
      continue;
    }
    rotations.push_back(u.rotation_deg);
    spdlog::info(
        "{}: standard deviation of rotation {:.3f} deg, centre {:.3f} % of the rig, focal "
        "length {:.3f} %, principal point {:.2f} px",
        out->cameras[c].id, u.rotation_deg, 100.0 * u.center_rel, 100.0 * u.focal_rel,
        u.principal_px);
  }
  const std::string detail =
      rotations.empty()
          ? std::string("not estimated")
          : fmt::format(
                "{} cameras, rotation standard deviation median {:.3f} deg, max {:.3f} deg{}",
                rotations.size(), UpperMedian(rotations),
                *std::max_element(rotations.begin(), rotations.end()),
                options.frames_per_group > 0
                    ? fmt::format(" (frames grouped by {})", options.frames_per_group)
                    : std::string());
  out->stages.push_back({"camera uncertainty", 0.0, SecondsSince(start), detail});
}

// A metric starting point: the scene, the view graph and pairs it was built from, and how
// each camera joined it (or why not).
struct MetricStart {
  MetricScene scene;
  ViewGraph graph;
  std::vector<PairwiseResult> pairs;
  std::vector<std::string> added_by;
  std::vector<std::string> reasons;
  bool focal_searched = false;
};

// The start from a common focal length (square pixels, principal points at the image
// centres) for `cameras` (`ids` their ids), recorded as a stage of `out`; nullopt if no focal
// length in the range gives one.
std::optional<MetricStart> FocalSearchStart(const std::vector<CameraModel>& cameras,
                                            const std::vector<std::string>& ids,
                                            std::vector<PairwiseResult> pairs,
                                            const CalibrationOptions& options,
                                            NetworkCalibration* out) {
  const auto start = Clock::now();
  FocalSearchResult search = SearchCommonFocal(cameras, pairs, options.focal, options.global);
  out->stages.push_back({"focal length search", 0.0, SecondsSince(start), search.detail});
  spdlog::info("focal length search: {}", search.detail);
  if (!search.ok) return std::nullopt;
  ApplyGlobalChoice(search.start, &pairs);
  ViewGraph graph = BuildViewGraph(ids, pairs);
  PoseChain chain = SceneFromGlobalStart(search.start, graph, search.cameras, options.known);
  for (std::string& how : chain.added_by) {
    if (!how.empty()) how += " (focal length search)";
  }
  return MetricStart{std::move(chain.scene),    std::move(graph),         std::move(pairs),
                     std::move(chain.added_by), std::move(chain.reasons), true};
}

// What RefineFromStart left to judge its start by.
struct RefinementOutcome {
  size_t rejected = 0;    // cameras the sanity gates rejected
  bool diverged = false;  // a re-matching round diverged (and was discarded)
};

// Takes `metric` to the calibration in `out`: bundle adjustment, re-matching rounds (a round
// that diverges discarded, and the rounds stopped), gauge, uncertainty, motion and sanity
// gates, pair checks.
RefinementOutcome RefineFromStart(MetricStart metric, const std::vector<CameraModel>& cameras,
                                  const std::vector<SilhouetteSequence>* sequences,
                                  const CalibrationOptions& options, Progress* progress,
                                  NetworkCalibration* out) {
  RefinementOutcome outcome;
  const size_t n = cameras.size();
  for (size_t c = 0; c < n; ++c) {
    out->placement[c].added_by = metric.added_by[c];
    out->placement[c].reason = metric.reasons[c];
  }
  std::vector<bool> used(metric.pairs.size(), false);
  if (options.intrinsics.fix_principal_point && !options.known_intrinsics) {
    // A principal point held fixed is the image centre, not the self-calibration's guess.
    for (size_t c = 0; c < n; ++c) {
      if (!metric.scene.present[c]) continue;
      metric.scene.cameras[c].K(0, 2) = 0.5 * (metric.scene.cameras[c].width - 1);
      metric.scene.cameras[c].K(1, 2) = 0.5 * (metric.scene.cameras[c].height - 1);
    }
  }
  // Without self-calibration nothing tells where the principal points are: they stay at the
  // image centres the focal length search assumed. Such a start is rougher, and its
  // distortion comes only from re-matching: a few more rounds.
  CalibrationOptions refine_options = options;
  if (metric.focal_searched) {
    refine_options.intrinsics.fix_principal_point = true;
    refine_options.rematch_rounds = std::max(refine_options.rematch_rounds, 3);
    refine_options.max_rematch_rounds =
        std::max(refine_options.max_rematch_rounds, refine_options.rematch_rounds);
  }
  const int most_rounds =
      refine_options.rematch_rounds == 0 ? 0 : refine_options.max_rematch_rounds;
  if (progress) progress->Restart("bundle adjustment", 1 + static_cast<size_t>(most_rounds));
  MetricRefinement refine(refine_options, out);
  // The uncertainty is that of the principal points free unless the user fixed them: held at
  // the image centres after a focal length search, they are an assumption, not a measurement.
  IntrinsicsModel uncertainty_model = refine_options.intrinsics;
  uncertainty_model.fixed = options.known_intrinsics;
  uncertainty_model.fix_principal_point = options.intrinsics.fix_principal_point;
  // After a focal length search, k2 waits for the first re-matching round: on the first
  // frontier points k1 and k2 together can make up for a focal length far off (Utrecht with an
  // experimental boundary model, seed 3: f 2 900 px, k1 -20, k2 380).
  refine.HoldSecondRadialTerm(metric.focal_searched);
  refine.Adjust(metric.graph, &metric.scene, "Euclidean bundle adjustment");
  refine.HoldSecondRadialTerm(false);
  uncertainty_model.radial_terms = refine.RadialTerms();
  if (progress) progress->Advance();
  for (size_t p = 0; p < metric.pairs.size(); ++p) {
    const ViewLink* link = metric.graph.Find(CameraIndex(cameras, metric.pairs[p].camera_i),
                                             CameraIndex(cameras, metric.pairs[p].camera_j));
    used[p] = link != nullptr && metric.scene.present[link->i] && metric.scene.present[link->j];
  }
  if (sequences != nullptr) {
    double previous_rms = 0.0;  // the last kept re-matched round's rms, 0 before the first
    for (int round = 0; round < most_rounds && !(progress && progress->cancelled()); ++round) {
      // After a focal length search the principal points were held at the image centres
      // while the cameras settled; the last round estimates them where the data hold them.
      if (metric.focal_searched && round + 1 == refine_options.rematch_rounds &&
          !options.intrinsics.fix_principal_point) {
        const std::string decision =
            FreePrincipalPoints(metric.scene, uncertainty_model, refine_options.bundle,
                                options.free_principal_max_sigma_px);
        refine.HoldPrincipalPoints(!decision.empty());
        out->stages.push_back({"principal points", 0.0, 0.0,
                               decision.empty() ? "estimated in the last round" : decision});
        spdlog::info("principal points: {}",
                     decision.empty() ? "estimated in the last round" : decision);
      }
      const auto start = Clock::now();
      std::vector<SilhouetteSequence> undistorted(n);
      ParallelFor(n, 0, [&](size_t c) {
        if (!metric.scene.present[c]) return;
        for (const SilhouetteSequence& s : *sequences) {
          if (s.camera_id == cameras[c].id)
            undistorted[c] = UndistortSequence(s, metric.scene.cameras[c]);
        }
      });
      const ViewGraph rematched = RematchedGraph(metric.scene, undistorted, out->sync);
      spdlog::info("re-matched frontier points of {} pairs ({:.1f} s)", rematched.links().size(),
                   SecondsSince(start));
      MetricScene before = metric.scene;
      const double rms = refine.Adjust(rematched, &metric.scene,
                                       fmt::format("re-matched bundle adjustment {}", round + 1));
      if (previous_rms > 0.0 && !(rms <= options.rematch_diverged_factor * previous_rms)) {
        metric.scene = std::move(before);
        outcome.diverged = true;
        const std::string verdict = fmt::format(
            "stopped: round {} diverged (rms {:.3f} -> {:.3f} px), its result discarded", round + 1,
            previous_rms, rms);
        spdlog::warn("re-matching {}", verdict);
        out->stages.push_back({"re-matching", 0.0, 0.0, verdict});
        break;
      }
      previous_rms = rms;
      for (size_t p = 0; p < metric.pairs.size(); ++p) {
        used[p] =
            used[p] || rematched.Find(CameraIndex(cameras, metric.pairs[p].camera_i),
                                      CameraIndex(cameras, metric.pairs[p].camera_j)) != nullptr;
      }
      if (progress) progress->Advance();
      const double turned = LargestRotationChange(before.cameras, metric.scene);
      const bool settled = turned < refine_options.rematch_settled_deg;
      if (round + 1 < refine_options.rematch_rounds) continue;
      if (!settled && round + 1 < most_rounds) continue;
      const std::string verdict =
          fmt::format("{} after {} rounds: the last turned a camera by {:.3f} deg at most",
                      settled ? "settled" : "stopped unsettled", round + 1, turned);
      spdlog::log(settled ? spdlog::level::info : spdlog::level::warn, "re-matching {}", verdict);
      out->stages.push_back({"re-matching", 0.0, 0.0, verdict});
      break;
    }
  }
  NormalizeGauge(&metric.scene, options.rig_radius);
  FillResult(metric.scene, out->sync, out);
  AddUncertainty(metric.scene, uncertainty_model, refine_options.bundle, options.uncertainty, out);
  RejectCamerasWithoutMotion(out);
  outcome.rejected = ApplyCalibrationGates(options.gates, out);
  if (outcome.rejected > 0) {
    out->stages.push_back(
        {"sanity gates", 0.0, 0.0,
         fmt::format("{} cameras rejected (see their reasons)", outcome.rejected)});
  }
  out->pairs = CheckPairs(out->cameras, out->placement, metric.pairs, used, options.corrected_px);
  return outcome;
}

}  // namespace

std::string CalibrationOptions::Validate() const {
  if (intrinsics.radial_terms < 0 || intrinsics.radial_terms > 2)
    return "radial distortion terms must be 0, 1 or 2";
  if (!(rig_radius > 0.0)) return "the rig radius must be positive";
  if (rematch_rounds < 0) return "re-matching rounds must not be negative";
  if (max_rematch_rounds < rematch_rounds)
    return "the most re-matching rounds must not be fewer than the least";
  if (!(rematch_settled_deg >= 0.0))
    return "the rotation change that settles re-matching must not be negative";
  if (!(rematch_diverged_factor > 1.0))
    return "the rms growth that marks a diverged re-matching round must exceed 1";
  if (!(distortion_gain > 0.0 && distortion_gain < 1.0))
    return "distortion_gain must lie between 0 and 1";
  if (!(free_principal_max_sigma_px >= 0.0))
    return "free_principal_max_sigma_px must not be negative";
  if (intrinsics.principal_point_sigma_px < 0.0 || !(intrinsics.observation_sigma_px > 0.0))
    return "the principal point prior needs a non-negative sigma and a positive observation sigma";
  if (!(bundle.loss_px > 0.0) || bundle.max_iterations < 1)
    return "bundle adjustment needs a positive loss scale and at least one iteration";
  if (!(corrected_px > 0.0)) return "the correction threshold must be positive";
  if (uncertainty.frames_per_group < 0)
    return "the uncertainty's frames per group must not be negative";
  if (const std::string why = gates.Validate(); !why.empty()) return why;
  return "";
}

NetworkCalibration CalibrateNetwork(const std::vector<CameraModel>& cameras,
                                    const std::vector<PairwiseResult>& estimated_pairs,
                                    const std::vector<SilhouetteSequence>* sequences,
                                    const CalibrationOptions& options, Progress* progress) {
  if (const std::string why = options.Validate(); !why.empty())
    throw InputError("calibration options: " + why);
  const size_t n = cameras.size();
  NetworkCalibration out;
  out.cameras = cameras;
  out.placement.assign(n, {});
  out.known_intrinsics = options.known_intrinsics;
  std::vector<std::string> ids;
  for (const CameraModel& c : cameras)
    ids.push_back(c.id);

  auto start = Clock::now();
  if (sequences != nullptr) {
    out.motion.resize(n);
    for (size_t c = 0; c < n; ++c) {
      const SilhouetteSequence* s = FindSequence(*sequences, cameras[c].id);
      out.motion[c] = s != nullptr ? MeasureMotionCoverage(*s, options.motion) : MotionCoverage{};
      out.motion[c].camera_id = cameras[c].id;
      if (s != nullptr) spdlog::info("{}: {}", cameras[c].id, out.motion[c].Describe());
    }
  }
  std::vector<PairwiseResult> pairs = estimated_pairs;
  // With known intrinsics the relative rotations pick each pair's candidate (and start the
  // poses); otherwise the triplets of fundamental matrices resolve what they can.
  GlobalStart global;
  if (options.known_intrinsics) {
    global = EstimateGlobalStart(cameras, pairs, options.global);
    out.stages.push_back(
        {"rotation averaging", 0.0, SecondsSince(start),
         global.ok ? fmt::format("{} cameras, {} pairs agree",
                                 std::count(global.present.begin(), global.present.end(), true),
                                 std::count_if(global.candidate.begin(), global.candidate.end(),
                                               [](int c) { return c >= 0; }))
                   : global.reason});
    if (global.ok) ApplyGlobalChoice(global, &pairs);
  }
  if (!global.ok) {
    const std::vector<AmbiguityDecision> decisions =
        ResolveAmbiguousPairs(cameras, &pairs, options.ambiguity);
    const auto resolved = std::count_if(decisions.begin(), decisions.end(),
                                        [](const AmbiguityDecision& d) { return d.resolved; });
    out.stages.push_back(
        {"ambiguous pairs", 0.0, SecondsSince(start),
         fmt::format("{} of {} resolved by triplet consistency", resolved, decisions.size())});
  }
  start = Clock::now();
  out.sync = SynchroniseNetwork(n, OffsetEdges(cameras, pairs), options.sync);
  out.stages.push_back({"synchronisation", 0.0, SecondsSince(start),
                        fmt::format("rms residual {:.3f} frames ({:.2f} sigma)",
                                    out.sync.rms_residual, out.sync.rms_normalised)});

  ViewGraph graph = BuildViewGraph(ids, pairs);
  std::optional<MetricScene> scene;
  std::vector<std::string> added_by(n), reasons(n);
  start = Clock::now();
  if (global.ok) {
    PoseChain start_scene = SceneFromGlobalStart(global, graph, cameras, options.known);
    out.stages.push_back(
        {"poses from rotation averaging", start_scene.last_bundle.rms_px, SecondsSince(start), ""});
    added_by = start_scene.added_by;
    reasons = start_scene.reasons;
    scene = std::move(start_scene.scene);
  } else if (options.known_intrinsics) {
    PoseChain chain = ChainKnownIntrinsics(graph, cameras, options.known, progress);
    out.stages.push_back(
        {"poses from essential matrices", chain.last_bundle.rms_px, SecondsSince(start), ""});
    added_by = chain.added_by;
    reasons = chain.reasons;
    if (std::count(chain.scene.present.begin(), chain.scene.present.end(), true) >= 2)
      scene = std::move(chain.scene);
  } else {
    ProjectiveReconstruction projective =
        ReconstructProjective(graph, cameras, options.projective, progress);
    out.stages.push_back({"projective reconstruction", projective.last_bundle.rms_px,
                          SecondsSince(start), fmt::format("{} cameras", projective.placed())});
    added_by = projective.added_by;
    reasons = projective.reasons;
    if (projective.placed() >= 3) {
      std::string why;
      start = Clock::now();
      const auto upgrade =
          SelfCalibrateLinear(projective.scene.cameras, projective.scene.present, &why);
      if (upgrade) scene = UpgradeToMetric(projective.scene, *upgrade, cameras, &why);
      if (scene) {
        // Intrinsics no lens has mean the upgrade went wrong (a near-critical configuration).
        // The linear upgrade is rough (the adjustment refines it): only a focal length out of
        // range, or a principal point or aspect ratio far outside the gates, refuses it.
        CalibrationGates start_gates = options.gates;
        start_gates.max_principal_offset = std::max(start_gates.max_principal_offset, 0.5);
        start_gates.max_aspect_error = std::max(start_gates.max_aspect_error, 0.5);
        for (size_t c = 0; c < n && scene; ++c) {
          if (!scene->present[c]) continue;
          const std::string failure = GateFailure(scene->cameras[c], 1.0, start_gates);
          if (failure.empty()) continue;
          why = fmt::format("implausible intrinsics for {}: {}", cameras[c].id, failure);
          scene.reset();
        }
      }
      out.stages.push_back({"self-calibration", 0.0, SecondsSince(start), why});
      if (!scene) {
        spdlog::info("self-calibration failed: {}", why);
        for (size_t c = 0; c < n; ++c) {
          if (projective.scene.present[c]) reasons[c] = "self-calibration failed: " + why;
        }
      }
    }
  }
  std::optional<MetricStart> metric;
  if (scene) {
    // `pairs` stay as they are for a second start.
    metric = MetricStart{std::move(*scene),   std::move(graph),   pairs,
                         std::move(added_by), std::move(reasons), false};
  } else if (!options.known_intrinsics) {
    // Self-calibration could not start the metric stage: search a common focal length.
    metric = FocalSearchStart(cameras, ids, pairs, options, &out);
  }
  if (!metric) {
    for (size_t c = 0; c < n; ++c) {
      out.placement[c].reason =
          reasons[c].empty() ? "the network could not be calibrated" : reasons[c];
      if (c < out.motion.size() && !out.motion[c].sufficient && out.motion[c].frames > 0)
        out.placement[c].reason = out.motion[c].advice + " (" + out.placement[c].reason + ")";
    }
    out.pairs = CheckPairs(out.cameras, out.placement, pairs,
                           std::vector<bool>(pairs.size(), false), options.corrected_px);
    return out;
  }
  // A self-calibrated start that leaves cameras failing the sanity gates or whose re-matching
  // diverged (from distorted silhouettes the linear upgrade can come out plausible enough to
  // start from, and wrong): the focal length search gives a second start, and the result with
  // more cameras calibrated, then the smaller reprojection error, is kept.
  const bool self_calibrated = !metric->focal_searched && !options.known_intrinsics;
  NetworkCalibration second = self_calibrated ? out : NetworkCalibration{};
  const RefinementOutcome first =
      RefineFromStart(std::move(*metric), cameras, sequences, options, progress, &out);
  if (self_calibrated && (first.rejected > 0 || first.diverged) &&
      !(progress && progress->cancelled())) {
    std::string why = "the self-calibrated start";
    if (first.diverged) why += "'s re-matching diverged";
    if (first.rejected > 0) {
      why += fmt::format("{} left {} cameras failing the sanity gates",
                         first.diverged ? " and it" : "", first.rejected);
    }
    spdlog::info("{}: starting again from a focal length search", why);
    std::optional<MetricStart> retry = FocalSearchStart(cameras, ids, pairs, options, &second);
    if (retry) RefineFromStart(std::move(*retry), cameras, sequences, options, progress, &second);
    const bool better =
        retry && (second.PlacedCount() > out.PlacedCount() ||
                  (second.PlacedCount() == out.PlacedCount() && second.rms_px < out.rms_px));
    const std::string verdict =
        fmt::format("{}; from a focal length search {} of {} cameras: {} kept", why,
                    retry ? second.PlacedCount() : 0, n, better ? "that start" : "the first");
    spdlog::info("second start: {}", verdict);
    if (better) out = std::move(second);
    out.stages.push_back({"second start", 0.0, 0.0, verdict});
  }
  if (progress) progress->Finish();
  return out;
}

}  // namespace silnet::aggregator

// Per-camera uncertainty from the final Euclidean bundle adjustment, against ground truth:
// on hand-made networks (exact two-view points, Gaussian pixel noise) the true errors must be
// of the size the deviations say, and scale with the noise; errors that runs of frames share
// must be explained by the deviations that group the frames; on a simulated capture the
// deviations must be small, explain the true errors, and grow for a camera that few frontier
// points hold; the uncertainty gate turns away the cameras above it.

#include "aggregator/calibration/camera_uncertainty.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "aggregator/calibration/calibration_gates.h"
#include "aggregator/calibration/ground_truth_comparison.h"
#include "aggregator/calibration/network_calibration.h"
#include "aggregator/pairwise/pairwise_job.h"
#include "shared/util/statistics.h"
#include "tests/aggregator/sim_sequences.h"

namespace silnet::aggregator {
namespace {

// A ring of `cameras` cameras (radius 3 m, 1.5 m up) looking at a person-sized volume, and
// `per_pair` noisy two-view points for every pair.
struct HandMadeNetwork {
  std::vector<CameraModel> truth;
  MetricScene scene;  // started from perturbed cameras
};

// With `bias_px`, the points of each run of `bias_frames` frames lie within 0.3 m of one
// place (a subject that moves on) and every camera's points of the run share a further error
// of that deviation (the errors of neighbouring frames' tangents repeat).
HandMadeNetwork MakeNetwork(int cameras, int per_pair, double noise_px, uint64_t seed,
                            double bias_px = 0.0, int bias_frames = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  HandMadeNetwork net;
  for (int c = 0; c < cameras; ++c) {
    const double a = 2.0 * EIGEN_PI * c / cameras + 0.2 * uniform(rng);
    CameraModel m;
    m.id = "cam" + std::to_string(c);
    m.width = 640;
    m.height = 480;
    const double f = 600.0 * (1.0 + 0.1 * uniform(rng));
    m.K << f, 0.0, 319.5 + 5.0 * uniform(rng), 0.0, f, 239.5 + 5.0 * uniform(rng), 0.0, 0.0, 1.0;
    const Eigen::Vector3d centre(3.0 * std::cos(a), 3.0 * std::sin(a), 1.5 + 0.3 * uniform(rng));
    m.R = LookAtRotation(centre, Eigen::Vector3d(0.2 * uniform(rng), 0.2 * uniform(rng), 1.0),
                         Eigen::Vector3d::UnitZ());
    m.t = -m.R * centre;
    net.truth.push_back(m);
  }
  const int runs = (per_pair + bias_frames - 1) / bias_frames;
  std::vector<std::vector<Eigen::Vector2d>> bias(
      net.truth.size(), std::vector<Eigen::Vector2d>(static_cast<size_t>(runs), {0.0, 0.0}));
  std::vector<Eigen::Vector3d> places;
  if (bias_px > 0.0) {
    for (auto& camera : bias) {
      for (Eigen::Vector2d& b : camera)
        b = bias_px * Eigen::Vector2d(gauss(rng), gauss(rng));
    }
    for (int run = 0; run < runs; ++run)
      places.emplace_back(0.9 * uniform(rng), 0.9 * uniform(rng), 1.3 + 0.9 * uniform(rng));
  }
  MetricScene& s = net.scene;
  s.present.assign(net.truth.size(), true);
  for (size_t i = 0; i < net.truth.size(); ++i) {
    for (size_t j = i + 1; j < net.truth.size(); ++j) {
      for (int k = 0; k < per_pair;) {
        const Eigen::Vector3d spread(uniform(rng), uniform(rng), uniform(rng));
        const Eigen::Vector3d x =
            bias_px > 0.0
                ? Eigen::Vector3d(places[static_cast<size_t>(k / bias_frames)] + 0.3 * spread)
                : Eigen::Vector3d(1.2 * spread + Eigen::Vector3d(0.0, 0.0, 1.3));
        const auto a = net.truth[i].Project(x), b = net.truth[j].Project(x);
        if (!a || !b || !net.truth[i].InImage(*a) || !net.truth[j].InImage(*b)) continue;
        TwoViewTrack t;
        t.camera_a = i;
        t.camera_b = j;
        t.x_a = *a + noise_px * Eigen::Vector2d(gauss(rng), gauss(rng)) +
                bias[i][static_cast<size_t>(k / bias_frames)];
        t.x_b = *b + noise_px * Eigen::Vector2d(gauss(rng), gauss(rng)) +
                bias[j][static_cast<size_t>(k / bias_frames)];
        t.frame = static_cast<uint64_t>(k++);
        s.tracks.push_back(t);
      }
    }
  }
  // A start off by about a degree, a few centimetres and a few percent of focal length.
  s.cameras = net.truth;
  for (CameraModel& c : s.cameras) {
    const Eigen::Vector3d w(0.01 * uniform(rng), 0.01 * uniform(rng), 0.01 * uniform(rng));
    const Eigen::Vector3d centre = c.Center() + 0.03 * Eigen::Vector3d(uniform(rng), 0, 0);
    c.R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * c.R;
    c.t = -c.R * centre;
    c.K(0, 0) *= 1.0 + 0.03 * uniform(rng);
    c.K(1, 1) = c.K(0, 0);
  }
  return net;
}

// Adjusts the network and returns the uncertainties and the true errors.
std::pair<std::vector<CameraUncertainty>, CalibrationErrors> AdjustAndCompare(
    HandMadeNetwork* net, const IntrinsicsModel& model = {},
    const UncertaintyOptions& uncertainty = {}) {
  const BundleOptions options;
  const BundleSummary summary = AdjustEuclidean(&net->scene, model, options);
  EXPECT_TRUE(summary.usable);
  const std::vector<CameraUncertainty> u =
      EstimateCameraUncertainty(net->scene, model, options, uncertainty);
  return {u, CompareWithGroundTruth(net->scene.cameras, net->scene.present, net->truth)};
}

// Squared errors in units of their deviation, per figure: about 1 on average if the
// deviations are right.
struct SquaredRatios {
  std::vector<double> rotation, centre, focal, principal;
};

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v)
    s += x;
  return s / static_cast<double>(v.size());
}

// Adjusts `seeds` 6-camera networks (`per_pair` points per pair and 0.3 px noise, plus
// `bias_px` per run of `bias_frames` frames) and collects every camera's squared ratios.
SquaredRatios RatiosOverSeeds(uint64_t seeds, int per_pair, double bias_px, int bias_frames,
                              const UncertaintyOptions& uncertainty) {
  SquaredRatios r;
  for (uint64_t seed = 1; seed <= seeds; ++seed) {
    HandMadeNetwork net = MakeNetwork(6, per_pair, 0.3, seed, bias_px, bias_frames);
    const auto [u, e] = AdjustAndCompare(&net, {}, uncertainty);
    EXPECT_EQ(e.cameras.size(), u.size());
    for (size_t c = 0; c < u.size() && c < e.cameras.size(); ++c) {
      EXPECT_TRUE(u[c].estimated) << "seed " << seed << " camera " << c;
      if (!u[c].estimated) continue;
      // Every camera has its own deviation, the ones the adjustment anchors on included.
      EXPECT_GT(u[c].rotation_deg, 1e-4);
      EXPECT_GT(u[c].center_rel, 1e-5);
      r.rotation.push_back(std::pow(e.cameras[c].rotation_deg / u[c].rotation_deg, 2));
      r.centre.push_back(std::pow(e.cameras[c].center_rel / u[c].center_rel, 2));
      r.focal.push_back(std::pow(e.cameras[c].focal_rel / u[c].focal_rel, 2));
      r.principal.push_back(std::pow(e.cameras[c].principal_px / u[c].principal_px, 2));
    }
  }
  std::printf("  mean squared error / variance: rotation %.2f, centre %.2f, focal %.2f, pp %.2f\n",
              Mean(r.rotation), Mean(r.centre), Mean(r.focal), Mean(r.principal));
  return r;
}

TEST(CameraUncertainty, DeviationsExplainTheErrorsOfNoisyNetworks) {
  // Independent noise: the residual variance alone, and with frames grouped (which must
  // not make the deviations much more cautious than they need be).
  for (const int frames : {0, 10}) {
    const SquaredRatios r = RatiosOverSeeds(8, 150, 0.0, 1, {frames});
    for (const auto* v : {&r.rotation, &r.centre, &r.focal, &r.principal}) {
      EXPECT_GT(Mean(*v), 0.4) << frames;
      EXPECT_LT(Mean(*v), 2.5) << frames;
      EXPECT_LT(*std::max_element(v->begin(), v->end()), 16.0) << frames;  // within 4 sigma
    }
  }
}

TEST(CameraUncertainty, GroupedFramesExplainTheErrorsOfCorrelatedNoise) {
  // The points of each run of 20 frames sit in one place and each camera's share a 1 px
  // error: taken as independent observations the deviations are several times too small;
  // grouped by 20 frames they explain the errors again.
  const SquaredRatios independent = RatiosOverSeeds(4, 300, 1.0, 20, {});
  const SquaredRatios grouped = RatiosOverSeeds(4, 300, 1.0, 20, {20});
  for (const auto& [a, b] : {std::pair{&independent.rotation, &grouped.rotation},
                             std::pair{&independent.centre, &grouped.centre},
                             std::pair{&independent.focal, &grouped.focal},
                             std::pair{&independent.principal, &grouped.principal}}) {
    EXPECT_GT(Mean(*a), 4.0);
    EXPECT_GT(Mean(*b), 0.3);
    EXPECT_LT(Mean(*b), 2.5);
  }
}

TEST(CameraUncertainty, ACameraSeenInOneRunLeavesTheOthersGrouped) {
  // Camera 5 keeps only the points of frames 0-19, one group: leaving that group out would
  // leave it unheld, so the group is kept, and the other cameras' deviations are still the
  // grouped ones that explain their errors.
  std::vector<double> independent, grouped;
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    HandMadeNetwork net = MakeNetwork(6, 300, 0.3, seed, 1.0, 20);
    std::erase_if(net.scene.tracks, [](const TwoViewTrack& t) {
      return (t.camera_a == 5 || t.camera_b == 5) && t.frame >= 20;
    });
    HandMadeNetwork copy = net;
    const auto [u_independent, e] = AdjustAndCompare(&net);
    const auto u_grouped = AdjustAndCompare(&copy, {}, {20}).first;
    for (size_t c = 0; c < 5; ++c) {
      ASSERT_TRUE(u_grouped[c].estimated) << c;
      independent.push_back(std::pow(e.cameras[c].rotation_deg / u_independent[c].rotation_deg, 2));
      grouped.push_back(std::pow(e.cameras[c].rotation_deg / u_grouped[c].rotation_deg, 2));
    }
    EXPECT_TRUE(u_grouped[5].estimated);
    // Its own figures are at least the independent ones (the two adjustments may differ in
    // the last digits).
    EXPECT_GE(u_grouped[5].rotation_deg, 0.999 * u_independent[5].rotation_deg);
  }
  std::printf(
      "  cameras 0-4, mean squared rotation error / variance: %.2f independent, %.2f grouped\n",
      Mean(independent), Mean(grouped));
  EXPECT_GT(Mean(independent), 4.0);
  EXPECT_LT(Mean(grouped), 2.5);
}

TEST(CameraUncertainty, ScalesWithTheNoise) {
  HandMadeNetwork quiet = MakeNetwork(6, 150, 0.2, 11);
  HandMadeNetwork noisy = MakeNetwork(6, 150, 0.8, 11);
  const auto u_quiet = AdjustAndCompare(&quiet).first;
  const auto u_noisy = AdjustAndCompare(&noisy).first;
  for (size_t c = 0; c < u_quiet.size(); ++c) {
    const double ratio = u_noisy[c].rotation_deg / u_quiet[c].rotation_deg;
    EXPECT_GT(ratio, 3.0) << c;
    EXPECT_LT(ratio, 5.0) << c;
  }
}

TEST(CameraUncertainty, AWeaklyHeldCameraIsLessCertain) {
  // With the principal points free, a ring looking at its middle leaves every camera's tilt
  // weakly held against its principal point; held at the truth, each camera's own points
  // decide.
  IntrinsicsModel fixed_pp;
  fixed_pp.fix_principal_point = true;
  for (const IntrinsicsModel& model : {IntrinsicsModel{}, fixed_pp}) {
    HandMadeNetwork full = MakeNetwork(6, 150, 0.3, 21);
    HandMadeNetwork weak = full;
    // Camera 2 keeps one in 30 of its points.
    std::vector<TwoViewTrack> kept;
    size_t seen = 0;
    for (const TwoViewTrack& t : weak.scene.tracks) {
      const bool touches = t.camera_a == 2 || t.camera_b == 2;
      if (!touches || seen++ % 30 == 0) kept.push_back(t);
    }
    weak.scene.tracks = kept;
    const auto u_full = AdjustAndCompare(&full, model).first;
    const auto [u, e] = AdjustAndCompare(&weak, model);
    std::printf("  principal points %s\n", model.fix_principal_point ? "fixed" : "free");
    for (size_t c = 0; c < u.size(); ++c) {
      std::printf(
          "  camera %zu: rotation %.3f deg (sigma %.3f, %.3f with all points), centre sigma "
          "%.3f %% (%.3f)\n",
          c, e.cameras[c].rotation_deg, u[c].rotation_deg, u_full[c].rotation_deg,
          100 * u[c].center_rel, 100 * u_full[c].center_rel);
    }
    const double factor = model.fix_principal_point ? 2.0 : 1.2;
    EXPECT_GT(u[2].rotation_deg, factor * u_full[2].rotation_deg);
    EXPECT_GT(u[2].center_rel, factor * u_full[2].center_rel);
    EXPECT_GT(u[2].focal_rel, factor * u_full[2].focal_rel);
    EXPECT_LT(e.cameras[2].rotation_deg, 4.0 * u[2].rotation_deg);
    // With the principal points held the others stay well below it (they still notice: the
    // weak camera's centre moves the alignment of all of them).
    for (size_t c = 0; c < u.size() && model.fix_principal_point; ++c) {
      if (c != 2) {
        EXPECT_LT(u[c].rotation_deg, 0.5 * u[2].rotation_deg) << c;
      }
    }
  }
}

TEST(CameraUncertainty, GateRejectsAnUncertainRotation) {
  CalibrationGates gates;
  gates.max_rotation_sigma_deg = 0.5;
  CameraUncertainty u;
  u.estimated = true;
  u.rotation_deg = 0.4;
  EXPECT_EQ(UncertaintyFailure(u, gates), "");
  u.rotation_deg = 0.7;
  EXPECT_NE(UncertaintyFailure(u, gates).find("uncertain by 0.70 deg"), std::string::npos)
      << UncertaintyFailure(u, gates);
  gates.max_rotation_sigma_deg = 0.0;
  EXPECT_EQ(UncertaintyFailure(u, gates), "");
  u.estimated = false;
  gates.max_rotation_sigma_deg = 0.5;
  EXPECT_EQ(UncertaintyFailure(u, gates), "");
}

// A simulated 8-camera ring (300 frames, seed 1), its pairs estimated once.
struct SimRing {
  testing::SimCapture capture;
  std::vector<PairwiseResult> pairs;
};

const SimRing& Ring() {
  static const SimRing ring = [] {
    sim::CameraNetworkOptions network;
    network.cameras = 8;
    network.layout = sim::RigLayout::kRing;
    network.max_offset = 15.0;
    network.seed = 1;
    sim::SceneOptions scene;
    scene.seed = 1;
    SimRing r;
    r.capture = testing::MakeSimCapture(network, scene, 300);
    PairwiseJobOptions options;
    options.pair.offset_min = -35;
    options.pair.offset_max = 35;
    r.pairs = EstimateAllPairs(r.capture.sequences, options).pairs;
    return r;
  }();
  return ring;
}

NetworkCalibration CalibrateRing(const std::vector<SilhouetteSequence>& sequences,
                                 const std::vector<PairwiseResult>& pairs,
                                 const CalibrationOptions& options) {
  return CalibrateNetwork(testing::UncalibratedCopies(Ring().capture.cameras), pairs, &sequences,
                          options);
}

// The ring calibrated with the default options, once.
const NetworkCalibration& Calibrated() {
  static const NetworkCalibration calibration =
      CalibrateRing(Ring().capture.sequences, Ring().pairs, {});
  return calibration;
}

CalibrationErrors Errors(const NetworkCalibration& calibration) {
  std::vector<bool> all(calibration.cameras.size(), true);
  return CompareWithGroundTruth(calibration.cameras, all, Ring().capture.cameras);
}

void Print(const NetworkCalibration& calibration, const CalibrationErrors& e) {
  for (const CalibrationStage& s : calibration.stages)
    std::printf("  stage %s: %.3f px, %.2f s, %s\n", s.name.c_str(), s.rms_px, s.seconds,
                s.detail.c_str());
  for (size_t c = 0; c < calibration.cameras.size(); ++c) {
    const CameraUncertainty& u = calibration.placement[c].uncertainty;
    std::printf(
        "  %s rotation %.3f deg (sigma %.3f), centre %.3f %% (sigma %.3f), focal %.3f %% "
        "(sigma %.3f), pp %.2f px (sigma %.2f), %zu observations\n",
        calibration.cameras[c].id.c_str(), e.cameras[c].rotation_deg, u.rotation_deg,
        100 * e.cameras[c].center_rel, 100 * u.center_rel, 100 * e.cameras[c].focal_rel,
        100 * u.focal_rel, e.cameras[c].principal_px, u.principal_px,
        calibration.placement[c].observations);
  }
}

TEST(CameraUncertainty, SimulatedRingIsCertainAndItsErrorsWithinFourSigma) {
  const NetworkCalibration& calibration = Calibrated();
  ASSERT_EQ(calibration.PlacedCount(), 8u);
  const CalibrationErrors e = Errors(calibration);
  Print(calibration, e);
  size_t explained = 0;
  for (size_t c = 0; c < calibration.cameras.size(); ++c) {
    const CameraUncertainty& u = calibration.placement[c].uncertainty;
    ASSERT_TRUE(u.estimated) << calibration.cameras[c].id;
    EXPECT_LT(u.rotation_deg, 0.3) << calibration.cameras[c].id;
    EXPECT_LT(u.center_rel, 0.01) << calibration.cameras[c].id;
    EXPECT_LT(u.focal_rel, 0.01) << calibration.cameras[c].id;
    explained += e.cameras[c].rotation_deg < 4.0 * u.rotation_deg ? 1 : 0;
  }
  EXPECT_GE(explained, 6u);
}

TEST(CameraUncertainty, SimulatedCameraWithFewFrontierPointsIsLessCertain) {
  // cam03 keeps one in 10 of its frames (the re-matching's frontier points) and of the
  // pairwise inliers of its pairs. Its rotation's deviation is mostly the tilt the free
  // principal point leaves (as for every camera of the ring), so it grows less than its own
  // points' share would say (measured 0.168 -> 0.249 deg, centre 0.091 -> 0.116 %).
  constexpr size_t kWeak = 3;
  std::vector<SilhouetteSequence> sequences = Ring().capture.sequences;
  SilhouetteSequence& thinned = sequences[kWeak];
  ASSERT_EQ(thinned.camera_id, "cam03");
  std::vector<SilhouetteFrame> frames;
  for (size_t k = 0; k < thinned.frames.size(); k += 10)
    frames.push_back(thinned.frames[k]);
  thinned.frames = frames;
  thinned.Index();
  std::vector<PairwiseResult> pairs = Ring().pairs;
  for (PairwiseResult& p : pairs) {
    if (p.camera_i != thinned.camera_id && p.camera_j != thinned.camera_id) continue;
    std::vector<TimedMatch> kept;
    for (size_t k = 0; k < p.inlier_matches.size(); k += 10)
      kept.push_back(p.inlier_matches[k]);
    p.inlier_matches = kept;
  }
  CalibrationOptions options;
  options.motion.min_moving_frames = 10;  // 30 frames left
  const NetworkCalibration weak = CalibrateRing(sequences, pairs, options);
  ASSERT_EQ(weak.PlacedCount(), 8u);
  const CalibrationErrors e = Errors(weak);
  Print(weak, e);
  const CameraUncertainty& u = weak.placement[kWeak].uncertainty;
  const CameraUncertainty& before = Calibrated().placement[kWeak].uncertainty;
  ASSERT_TRUE(u.estimated);
  EXPECT_LT(weak.placement[kWeak].observations, Calibrated().placement[kWeak].observations / 3);
  EXPECT_GT(u.rotation_deg, 1.3 * before.rotation_deg);
  EXPECT_GT(u.center_rel, 1.15 * before.center_rel);
  EXPECT_GT(u.focal_rel, 1.1 * before.focal_rel);
  EXPECT_LT(e.cameras[kWeak].rotation_deg, 4.0 * u.rotation_deg);
}

TEST(CameraUncertainty, GateTurnsAwayTheSimulatedCamerasAboveIt) {
  NetworkCalibration calibration = Calibrated();
  std::vector<double> sigmas;
  for (const CameraPlacement& p : calibration.placement)
    sigmas.push_back(p.uncertainty.rotation_deg);
  CalibrationGates gates;
  gates.max_rotation_sigma_deg = UpperMedian(sigmas);
  const auto above = static_cast<size_t>(std::count_if(
      sigmas.begin(), sigmas.end(), [&](double s) { return s > gates.max_rotation_sigma_deg; }));
  ASSERT_GT(above, 0u);
  EXPECT_EQ(ApplyCalibrationGates(gates, &calibration), above);
  for (size_t c = 0; c < sigmas.size(); ++c) {
    const CameraPlacement& p = calibration.placement[c];
    EXPECT_EQ(p.placed, sigmas[c] <= gates.max_rotation_sigma_deg) << c;
    if (!p.placed) {
      EXPECT_NE(p.reason.find("rotation is uncertain"), std::string::npos) << p.reason;
    }
  }
  // The default gate passes them all.
  NetworkCalibration defaults = Calibrated();
  EXPECT_EQ(ApplyCalibrationGates({}, &defaults), 0u);
}

}  // namespace
}  // namespace silnet::aggregator

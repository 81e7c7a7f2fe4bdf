// Calibration from the silhouettes of a real capture (the shared data folder's Utrecht
// 4-camera room: four people walking, strong lens distortion, the capture's own checkerboard
// calibration as the reference), and the parts that make it hold on real data: the sanity
// gates, triplet consistency, and clear errors for incomplete pairwise results.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <tuple>

#include "aggregator/calibration/calibrate_job.h"
#include "aggregator/calibration/calibration_gates.h"
#include "aggregator/calibration/epipolar_consistency.h"
#include "aggregator/calibration/frontier_rematching.h"
#include "aggregator/calibration/triplet_consistency.h"
#include "aggregator/hulls/hull_reprojection.h"
#include "aggregator/hulls/polyhedral_hull.h"
#include "aggregator/hulls/real_datasets.h"
#include "aggregator/pairwise/pairwise_job.h"
#include "shared/geometry/epipolar.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"
#include "tests/support/real_data.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

const std::filesystem::path kUtrecht =
    std::filesystem::path(SILNET_SHARED_DATA_DIR) / "utrecht-4persons-4cam";
constexpr char kMaskVideo[] = "foreground_cropped.avi";

// Median epipolar-tangent transfer error of every camera pair under `cameras`, on the
// silhouettes with each camera's distortion taken out.
std::vector<PairResidual> TangentResiduals(std::vector<CameraModel> cameras,
                                           const std::vector<SilhouetteSequence>& raw) {
  std::vector<SilhouetteSequence> undistorted;
  for (const CameraModel& c : cameras)
    undistorted.push_back(UndistortSequence(*FindSequence(raw, c.id), c));
  for (CameraModel& c : cameras)
    c.dist.setZero();
  return MeasureEpipolarResiduals(cameras, std::vector<bool>(cameras.size(), true), undistorted);
}

// The angle, degrees, between the rotation from camera j to camera i in one calibration
// (a_i, a_j) and in another (b_i, b_j): what no choice of world frame changes.
double RelativeRotationDeg(const CameraModel& a_i, const CameraModel& a_j, const CameraModel& b_i,
                           const CameraModel& b_j) {
  const Eigen::Matrix3d a = a_i.R * a_j.R.transpose(), b = b_i.R * b_j.R.transpose();
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / EIGEN_PI;
}

// Frame `frame` of every Utrecht camera's mask video, thresholded (grey above 128).
std::vector<cv::Mat> UtrechtMasks(const std::vector<CameraModel>& cameras, int frame) {
  std::vector<cv::Mat> masks;
  for (const CameraModel& c : cameras) {
    cv::VideoCapture video((kUtrecht / c.id / kMaskVideo).string());
    video.set(cv::CAP_PROP_POS_FRAMES, frame);
    cv::Mat bgr, grey;
    EXPECT_TRUE(video.read(bgr)) << c.id << " frame " << frame;
    if (bgr.empty()) return {};
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    masks.push_back(grey > 128);
  }
  return masks;
}

// Silhouette pixels the exact hull misses farther than 2 px from the outline, and pixels it
// adds, summed over the views of every frame in `frames` whose hull both calibrations close.
struct HullCoverage {
  size_t silhouette = 0, missed_far = 0, spurious = 0;
  int frames = 0;
};

std::pair<HullCoverage, HullCoverage> CompareHullCoverage(const std::vector<CameraModel>& given,
                                                          const std::vector<CameraModel>& ours,
                                                          const std::vector<int>& frames) {
  HullCoverage a, b;
  for (int frame : frames) {
    const std::vector<cv::Mat> masks = UtrechtMasks(given, frame);
    if (masks.empty()) continue;
    const PolyhedralHullResult hull_a = ComputePolyhedralHull(given, masks);
    const PolyhedralHullResult hull_b = ComputePolyhedralHull(ours, masks);
    if (!hull_a.success || !hull_b.success) continue;
    for (auto [hull, cameras, sum] : {std::tuple{&hull_a, &given, &a}, {&hull_b, &ours, &b}}) {
      for (const ViewReprojection& v : MeasureHullReprojection(hull->mesh, *cameras, masks)) {
        sum->silhouette += v.silhouette_pixels;
        sum->missed_far += v.missed_far_pixels;
        sum->spurious += v.spurious_pixels;
      }
      ++sum->frames;
    }
  }
  return {a, b};
}

// Runs the calibrate job on the Utrecht capture and checks what every run must give: all
// four cameras calibrated, and the silhouettes' epipolar tangents explained at least as well
// as by the capture's own calibration, pair by pair. `seed` seeds the random choices.
CalibrateJobResult CalibrateUtrecht(bool with_intrinsics, const testing::TempDir& dir,
                                    uint64_t seed = 1) {
  const std::vector<CameraModel> truth = LoadUtrechtCameras(kUtrecht, 10.0);
  SaveCalibration(dir / "truth.yaml", truth);
  CalibrateJobConfig config;
  config.input = kUtrecht;
  config.output = dir / "out";
  config.mask_video = kMaskVideo;
  config.ground_truth = dir / "truth.yaml";
  config.report = false;
  config.pairwise.pair.seed = seed;
  config.pairwise.pair.offset_min = -35.0;  // the command line's default search range
  config.pairwise.pair.offset_max = 35.0;
  if (with_intrinsics)
    config.intrinsics = dir / "truth.yaml";
  else
    config.calibration.intrinsics.radial_terms = 2;
  const CalibrateJobResult result = RunCalibrateJob(config, nullptr);
  const NetworkCalibration& c = result.calibration;
  EXPECT_EQ(c.PlacedCount(), 4u);
  for (size_t k = 0; k < c.cameras.size(); ++k)
    EXPECT_TRUE(c.placement[k].placed) << c.cameras[k].id << ": " << c.placement[k].reason;
  // Four people walking across the room: every camera saw enough motion (measured: 36-67 % of
  // the image, 81-94 % of the tangent directions, 270-271 of 272 frames).
  EXPECT_EQ(c.motion.size(), 4u);
  for (const MotionCoverage& m : c.motion) {
    EXPECT_TRUE(m.sufficient) << m.camera_id << ": " << m.advice;
    EXPECT_GT(m.image_share, 0.3) << m.camera_id;
  }
  if (c.PlacedCount() != 4) return result;
  for (size_t k = 0; k < c.cameras.size() && result.errors; ++k) {
    const CameraUncertainty& u = c.placement[k].uncertainty;
    std::printf("  %s rotation off the capture's by %.3f deg; its standard deviation %.3f deg\n",
                c.cameras[k].id.c_str(), result.errors->cameras[k].rotation_deg, u.rotation_deg);
  }

  SequenceLoadOptions load;
  load.mask_video = kMaskVideo;
  const std::vector<SilhouetteSequence> raw = LoadSequences(kUtrecht, load);
  const std::vector<PairResidual> given = TangentResiduals(truth, raw);
  const std::vector<PairResidual> estimated = TangentResiduals(c.cameras, raw);
  for (size_t p = 0; p < given.size(); ++p) {
    std::printf("  %s-%s tangent transfer: capture's calibration %.2f px, silnet's %.2f px\n",
                truth[given[p].i].id.c_str(), truth[given[p].j].id.c_str(), given[p].median_px,
                estimated[p].median_px);
    EXPECT_LE(estimated[p].median_px, given[p].median_px);
  }

  // The exact hull of the four walkers explains the masks at least as well (every 12th frame;
  // those where someone is cut by an image border give no hull and are left out).
  std::vector<int> frames;
  for (int f = 6; f < 272; f += 12)
    frames.push_back(f);
  const auto [theirs, silnets] = CompareHullCoverage(truth, c.cameras, frames);
  const auto share = [](size_t n, size_t of) { return 100.0 * static_cast<double>(n) / of; };
  std::printf(
      "  hull over %d frames: missed beyond 2 px %.2f %% (capture's calibration) vs %.2f %% "
      "(silnet's), added %.2f %% vs %.2f %%\n",
      silnets.frames, share(theirs.missed_far, theirs.silhouette),
      share(silnets.missed_far, silnets.silhouette), share(theirs.spurious, theirs.silhouette),
      share(silnets.spurious, silnets.silhouette));
  EXPECT_GE(silnets.frames, 5);
  EXPECT_LE(share(silnets.missed_far, silnets.silhouette),
            share(theirs.missed_far, theirs.silhouette));
  // Measured 0.35 vs 0.34 % added: equal within what a pixel of outline makes.
  EXPECT_LE(share(silnets.spurious, silnets.silhouette),
            1.1 * share(theirs.spurious, theirs.silhouette));
  return result;
}

TEST(RealCaptureCalibration, UtrechtWithCheckerboardIntrinsics) {
  SILNET_REQUIRE_REAL_DATA(kUtrecht);
  testing::TempDir dir;
  const CalibrateJobResult result = CalibrateUtrecht(true, dir);
  ASSERT_TRUE(result.errors.has_value());
  const CalibrationErrors& e = *result.errors;
  std::printf("  rotation against the capture's calibration: median %.3f deg, max %.3f deg\n",
              e.median_rotation_deg, e.max_rotation_deg);
  // Measured 0.98 / 1.44 deg here (seed 1); 0.83-0.90 / 1.07-1.44 deg over seeds 1-10
  // (with a single round of re-matching 1.16 / 1.76 deg, and 0.78-1.25 / 1.06-1.83 over the
  // seeds). The capture's own calibration explains the tangents 1.2-4.2x worse (9-12 px median
  // on the pairs with cam4) than silnet's, so most of this is its error.
  EXPECT_LT(e.median_rotation_deg, 1.1);
  EXPECT_LT(e.max_rotation_deg, 1.6);
  EXPECT_LT(e.max_offset_frames, 0.1);  // the capture is synchronised; offsets were estimated
}

// The pairs of this capture often have several solutions of similar support, which seeds
// reach differently; the network must place every camera whatever the seed. The relative
// poses decomposed from the pairs' fundamental matrices lay up to 26 deg from the capture's
// calibration and few pairs agreed within the rotation tolerance, until they were refined as
// essential matrices on their correspondences. Before, seeds 5, 6 and 7 placed 3, 3 and 2 of
// the four cameras, and all four on only 4 of seeds 1-10 (now on all ten). Re-matching until
// the cameras settle brings the seeds' results together: the rotation between two cameras
// (which no choice of world frame changes) differs between any two of seeds 1-10 by at most
// 0.23 deg, against 0.62 deg with a single round.
TEST(RealCaptureCalibration, UtrechtWithCheckerboardIntrinsicsWhateverTheSeed) {
  SILNET_REQUIRE_REAL_DATA(kUtrecht);
  std::vector<std::vector<CameraModel>> results;
  for (const uint64_t seed : {5u, 6u, 7u}) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    testing::TempDir dir;
    const CalibrateJobResult result = CalibrateUtrecht(true, dir, seed);
    ASSERT_TRUE(result.errors.has_value());
    std::printf(
        "  seed %u: rotation against the capture's calibration: median %.3f, max %.3f deg\n",
        static_cast<unsigned>(seed), result.errors->median_rotation_deg,
        result.errors->max_rotation_deg);
    EXPECT_LT(result.errors->max_rotation_deg, 1.6);  // measured 1.08-1.26 deg
    results.push_back(result.calibration.cameras);
  }
  // Every pair's relative rotation as seed 5 gives it (measured: at most 0.11 deg apart over
  // these seeds; 0.29 deg with a single round of re-matching).
  for (size_t i = 0; i < 4; ++i) {
    for (size_t j = i + 1; j < 4; ++j) {
      for (size_t s = 1; s < results.size(); ++s) {
        EXPECT_LT(RelativeRotationDeg(results[s][i], results[s][j], results[0][i], results[0][j]),
                  0.15)
            << results[0][i].id << "-" << results[0][j].id << ", run " << s;
      }
    }
  }
}

// Without any calibration the pairs are estimated on the distorted silhouettes, whose
// tangents no pinhole F fits within 2 px: the local fits accept 3 px there. With 2 px, seeds
// 2-4 left 2 of 6 pairs failed and calibrated no camera at all (seeds 1, 5, 6 all four).
TEST(RealCaptureCalibration, UtrechtWithoutAnyCalibration) {
  SILNET_REQUIRE_REAL_DATA(kUtrecht);
  // Seed 7's self-calibrated start diverges in its second re-matching round (rms 1.1 -> 35 px,
  // then 3e7 px had the rounds gone on): the round is discarded, the rounds stop, and the
  // focal length search gives the second start that calibrates all four (the first's cameras
  // fail the sanity gates anyway). The other seeds' rounds never grow the error.
  for (const uint64_t seed : {3u, 4u, 7u}) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    testing::TempDir dir;
    const CalibrateJobResult result = CalibrateUtrecht(false, dir, seed);
    const std::vector<CalibrationStage>& stages = result.calibration.stages;
    const auto second_start =
        std::find_if(stages.begin(), stages.end(),
                     [](const CalibrationStage& s) { return s.name == "second start"; });
    EXPECT_EQ(second_start != stages.end(), seed == 7);
    if (second_start != stages.end()) {
      EXPECT_NE(second_start->detail.find("re-matching diverged"), std::string::npos)
          << second_start->detail;
    }
    for (const CalibrationStage& s : stages)
      EXPECT_EQ(s.detail.find("diverged (rms"), std::string::npos) << s.detail;
    ASSERT_TRUE(result.errors.has_value());
    const CalibrationErrors& e = *result.errors;
    std::printf("  seed %u: focal %.2f %%, rotation median %.3f deg, max %.3f deg\n",
                static_cast<unsigned>(seed), 100 * e.median_focal_rel, e.median_rotation_deg,
                e.max_rotation_deg);
    // Measured: focal 3.4-5.1 %, rotation 2.6-2.9 / 2.8-3.3 deg over seeds 1-10 (principal
    // points held at the centre; the capture's are up to 20 px off it).
    EXPECT_LT(e.median_focal_rel, 0.06);
    EXPECT_LT(e.max_rotation_deg, 4.0);
    for (const CameraModel& c : result.calibration.cameras)
      EXPECT_LT(c.dist[0], -0.05) << c.id << ": the strong barrel distortion is found";
  }
}

// A person sitting still (the Utrecht seated capture, colour video segmented by the node's
// pipeline): no camera may come out calibrated, and each says it saw too little motion.
TEST(RealCaptureCalibration, UtrechtSeatedIsReportedAsTooLittleMotion) {
  const std::filesystem::path seated =
      std::filesystem::path(SILNET_SHARED_DATA_DIR) / "utrecht-seated-4cam";
  SILNET_REQUIRE_REAL_DATA(seated);
  testing::TempDir dir;
  CalibrateJobConfig config;
  config.input = seated;
  config.output = dir / "out";
  config.frame_video = "video.avi";
  config.report = false;
  const CalibrateJobResult result = RunCalibrateJob(config, nullptr);
  const NetworkCalibration& c = result.calibration;
  EXPECT_EQ(c.PlacedCount(), 0u);
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "calibration.yaml"));
  ASSERT_EQ(c.motion.size(), c.cameras.size());
  for (size_t k = 0; k < c.cameras.size(); ++k) {
    std::printf("  %s: %s\n", c.cameras[k].id.c_str(), c.motion[k].Describe().c_str());
    EXPECT_FALSE(c.motion[k].sufficient) << c.cameras[k].id;
    EXPECT_NE(c.placement[k].reason.find("too little motion"), std::string::npos)
        << c.placement[k].reason;
  }
}

TEST(CalibrationGates, RejectWhatNoLensGives) {
  CameraModel c;
  c.width = 640;
  c.height = 480;
  c.K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  const CalibrationGates gates;
  EXPECT_EQ(GateFailure(c, 1.0, gates), "");
  CameraModel tiny = c;
  tiny.K(0, 0) = tiny.K(1, 1) = 30.0;
  EXPECT_NE(GateFailure(tiny, 1.0, gates).find("focal length"), std::string::npos);
  CameraModel off = c;
  off.K(0, 2) = 700.0;
  EXPECT_NE(GateFailure(off, 1.0, gates).find("principal point"), std::string::npos);
  CameraModel stretched = c;
  stretched.K(1, 1) = 800.0;
  EXPECT_NE(GateFailure(stretched, 1.0, gates).find("aspect"), std::string::npos);
  EXPECT_NE(GateFailure(c, 0.6, gates).find("in front"), std::string::npos);
}

TEST(TripletConsistency, TrueCamerasAgreeAndAWrongPairDoesNot) {
  std::vector<CameraModel> cameras(3);
  const Eigen::Vector3d centres[3] = {{3, 0, 1}, {0, 3, 1.2}, {-2.5, -2, 0.8}};
  for (int k = 0; k < 3; ++k) {
    cameras[k].width = 640;
    cameras[k].height = 480;
    cameras[k].K << 520, 0, 325, 0, 520, 238, 0, 0, 1;
    cameras[k].R = LookAtRotation(centres[k], Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
    cameras[k].t = -cameras[k].R * centres[k];
  }
  const ViewSize size{640, 480};
  const Eigen::Matrix3d f01 = FundamentalFromCameras(cameras[0], cameras[1]);
  const Eigen::Matrix3d f02 = FundamentalFromCameras(cameras[0], cameras[2]);
  const Eigen::Matrix3d f12 = FundamentalFromCameras(cameras[1], cameras[2]);
  EXPECT_LT(TripletInconsistency(f01, f02, f12, size, size, size), 1e-6);
  CameraModel turned = cameras[1];
  turned.R = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix() * turned.R;
  turned.t = -turned.R * centres[1];
  const Eigen::Matrix3d wrong = FundamentalFromCameras(cameras[0], turned);
  // One camera turned by 2.9 deg for this pair only: measured 3.5 px (the epipole constraints
  // see only part of such an error; the resolution's threshold is 4 px with a 3x margin).
  EXPECT_GT(TripletInconsistency(wrong, f02, f12, size, size, size), 2.0);
}

TEST(PairsYaml, ReusingPairsWithoutTheirMatchesIsAClearError) {
  testing::TempDir dir;
  PairwiseJobResult result;
  const std::string a = "cam_a", b = "cam_b";
  PairwiseResult p;
  p.camera_i = a;
  p.camera_j = b;
  p.status = PairStatus::kOk;
  p.F << 0, 0, 1, 0, 0, 0, -1, 0, 0;
  p.inliers = 1;
  TimedMatch m;
  m.x_i = {10.0, 20.0};
  m.x_j_a = m.x_j_b = {30.0, 40.0};
  p.inlier_matches.push_back(m);
  result.pairs.push_back(p);
  WritePairsYaml(dir / "pairs.yaml", result);
  EXPECT_THAT([&] { ReadPairsYaml(dir / "pairs.yaml", dir / "matches"); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("matches")))
      << "without matches/";
  WriteMatchesCsv(dir / "matches", result);
  EXPECT_EQ(ReadPairsYaml(dir / "pairs.yaml", dir / "matches").front().inlier_matches.size(), 1u);
}

// A pairs.yaml edited or cut short is an InputError naming the file, not an OpenCV assertion
// or a 16 GB F.
TEST(PairsYaml, MalformedPairsAreClearErrors) {
  testing::TempDir dir;
  const auto refused = [&](const std::string& text, const std::string& fragment) {
    std::ofstream(dir / "pairs.yaml") << "%YAML:1.0\n---\n" << text;
    EXPECT_THAT([&] { ReadPairsYaml(dir / "pairs.yaml", {}); },
                ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(fragment)))
        << text;
  };
  const std::string f =
      "F: !!opencv-matrix { rows: 3, cols: 3, dt: d, data: [0, 0, 1, 0, 0, 0, -1, 0, 0] }";
  refused("pairs: [ 1 ]\n", "pairs.yaml: malformed (");
  refused("pairs: [ { i: a, j: b, status: ok, F: [1, 2] } ]\n", "pair a-b: 'F'");
  refused(
      "pairs: [ { i: a, j: b, status: ok, F: !!opencv-matrix { rows: 60000, cols: 60000, dt: d, "
      "data: [1] } } ]\n",
      "pair a-b: 'F' has 3600000000 entries, expected 9");
  refused("pairs: [ { i: a, j: b, status: ok, " + f + ", offset: .NaN } ]\n",
          "pair a-b has a non-finite offset");
  refused("pairs: [ { i: a, j: a, status: ok, " + f + ", offset: 1 } ]\n",
          "pair 'a-a' needs two different cameras");
  refused("pairs: [ { j: b, status: ok, " + f + ", offset: 1 } ]\n",
          "pair '-b' needs two different cameras");
  refused("pairs: [ { i: a, j: b, status: ok, " + f + ", offset: 1, inliers: -3 } ]\n",
          "pair a-b has a negative count");
  refused("pairs: [ { i: a, j: b, status: ok, " + f + ", offset: 1, offset_sigma: -1 } ]\n",
          "pair a-b has a negative or non-finite offset_sigma or residual");
  refused("pairs: [ { i: a, j: b, status: ok, " + f + ", offset: 1, residual: .Inf } ]\n",
          "pair a-b has a negative or non-finite offset_sigma or residual");
  std::ofstream(dir / "pairs.yaml")
      << "%YAML:1.0\n---\npairs: [ { i: a, j: b, status: ok, " << f << ", offset: 2.5 } ]\n";
  const std::vector<PairwiseResult> pairs = ReadPairsYaml(dir / "pairs.yaml", {});
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].F(0, 2), 1.0);
  EXPECT_EQ(pairs[0].F(2, 0), -1.0);
  EXPECT_EQ(pairs[0].offset, 2.5);
}

}  // namespace
}  // namespace silnet::aggregator

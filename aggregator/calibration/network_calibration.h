#pragma once
// Calibrating and synchronising a camera network from its pairwise epipolar geometries and
// offsets (thesis chapter 3), stage by stage:
//   synchronisation   offsets graph, cycle test, weighted least squares (3.3)
//   projective        view graph, best triplet, cameras added through two links, projective
//                     bundle adjustment after each (3.2.1-3.2.4)
//   metric            linear self-calibration, then Euclidean bundle adjustment (3.2.5);
//                     with known intrinsics instead: poses from essential matrices (8.2.1)
//   distortion        radial distortion k1, k2 in the bundle adjustment, if asked
//   re-matching       frontier points of every calibrated pair recomputed from the cameras
//                     and offsets on undistorted silhouettes, then a last adjustment
//   closing the loop  every pairwise estimate checked against the final cameras
// Expected failures (a camera that cannot be placed, a self-calibration that fails) are
// results with reasons, not exceptions.

#include <string>
#include <vector>

#include "aggregator/calibration/ambiguity_resolution.h"
#include "aggregator/calibration/calibration_gates.h"
#include "aggregator/calibration/calibration_result.h"
#include "aggregator/calibration/camera_uncertainty.h"
#include "aggregator/calibration/euclidean_bundle_adjustment.h"
#include "aggregator/calibration/focal_search.h"
#include "aggregator/calibration/global_start.h"
#include "aggregator/calibration/known_intrinsics.h"
#include "aggregator/calibration/projective_reconstruction.h"
#include "aggregator/pairwise/silhouette_sequence.h"
#include "aggregator/sync/network_sync.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the network calibration; defaults suit a rig of ordinary video cameras.
struct CalibrationOptions {
  IntrinsicsModel intrinsics;     // what the Euclidean bundle adjustment estimates
  bool known_intrinsics = false;  // the input cameras carry trusted K and distortion
  AmbiguityOptions ambiguity;     // picking among an ambiguous pair's solutions
  ProjectiveOptions projective;
  KnownIntrinsicsOptions known;
  GlobalStartOptions global;     // the start with known intrinsics (and after a focal search)
  FocalSearchOptions focal;      // when self-calibration cannot start the metric stage
  CalibrationGates gates;        // every calibrated camera must pass these
  MotionCoverageOptions motion;  // and its silhouettes must have moved this much
  SyncOptions sync;
  BundleOptions bundle;                 // the Euclidean adjustments
  size_t final_tracks_per_link = 1500;  // correspondences per pair in the metric stages
  // Re-matching rounds when silhouettes are given: at least rematch_rounds, then more while
  // the last round still turned some camera by rematch_settled_deg or more, up to
  // max_rematch_rounds. On the Utrecht capture a round from a rough start moves the cameras
  // by 0.1-0.2 deg for two or three rounds; simulated rigs are settled after one (the second
  // turns no camera by 0.015 deg). rematch_rounds 0 turns re-matching off.
  int rematch_rounds = 1;
  int max_rematch_rounds = 4;
  double rematch_settled_deg = 0.02;
  // A re-matching round after the first whose adjustment ends with an rms reprojection error
  // above rematch_diverged_factor times the previous round's has diverged: its result is
  // discarded and re-matching stops (consecutive rounds differ by a few per cent; Utrecht's
  // diverging self-calibrated start of seed 7 went 1.1 -> 35 -> 3e7 px).
  double rematch_diverged_factor = 2.0;
  // With intrinsics.radial_terms 0 and unknown intrinsics: the first Euclidean adjustment is
  // tried again with k1 and k2, and they are estimated from then on if they bring the rms
  // reprojection error down by more than distortion_gain (a share of it). Lenses without
  // distortion gain nothing (simulated rings: 0.103 -> 0.103 px); the simulator's widest,
  // |k1| up to 0.3, a third (0.240 -> 0.153 px).
  bool detect_distortion = false;
  double distortion_gain = 0.05;
  // After a focal length search (principal points at the image centres) the last re-matching
  // round frees the principal points if their standard deviation, free, is within this (px).
  double free_principal_max_sigma_px = 5.0;
  // The reported uncertainty (and its gate) groups the frontier points of this many
  // consecutive frames (camera_uncertainty.h): on the Utrecht capture, groups of 25 frames
  // raise the rotation deviations 1.2-1.5x over independent points (their errors repeat from
  // frame to frame); on simulated rigs they hardly move (0-10 %).
  UncertaintyOptions uncertainty{25};
  double rig_radius = 1.0;    // world scale: mean distance of the cameras from their centroid
  double corrected_px = 1.0;  // pairwise estimates whose matches lie further off are "corrected"

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// Calibrates `cameras` (id, image size, fps; with known_intrinsics also K and dist) from
// `pairs` (the pairwise job's results, cameras named by id; ambiguous pairs are resolved by
// the other pairs where they can be, see ambiguity_resolution.h). `sequences`, when given, are the
// cameras' silhouettes (matched by camera id) for the re-matching stage. Throws InputError
// for invalid options.
NetworkCalibration CalibrateNetwork(const std::vector<CameraModel>& cameras,
                                    const std::vector<PairwiseResult>& pairs,
                                    const std::vector<SilhouetteSequence>* sequences,
                                    const CalibrationOptions& options,
                                    Progress* progress = nullptr);

}  // namespace silnet::aggregator

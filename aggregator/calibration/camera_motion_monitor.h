#pragma once
// Detection of a camera that moved after the network was calibrated. The epipolar residuals
// of every camera pair (epipolar_consistency.h) are measured on a baseline window known to
// match the calibration, then on each new window. A pair has jumped when its median residual
// exceeds both jump_factor times its baseline and its baseline plus min_jump_px. A camera is
// suspect when most of its measured pairs jumped while few of the pairs without it did (a
// moved camera spoils only its own pairs; a badly segmented moment or a wrong calibration
// spoils them all), and reported moved once it stays suspect for `confirmations` windows in
// a row.

#include <string>
#include <vector>

#include "aggregator/calibration/epipolar_consistency.h"
#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Settings of the monitor.
struct CameraMotionOptions {
  double jump_factor = 3.0;
  double min_jump_px = 1.5;
  size_t min_matches = 20;           // per pair and window
  double own_pairs_jumped = 0.6;     // share of a camera's measured pairs that must jump
  double other_pairs_jumped = 0.34;  // share of the other measured pairs that may jump
  int confirmations = 2;

  // A readable reason if the options are unusable, empty if they are fine.
  std::string Validate() const;
};

// One camera's state after a window.
struct CameraMotionVerdict {
  size_t camera = 0;  // index into the calibration's cameras
  std::string camera_id;
  double residual_px = -1.0;  // median over its measured pairs of their median residual
  double baseline_px = -1.0;  // the same over the baseline window
  size_t pairs_measured = 0;
  size_t pairs_jumped = 0;
  bool suspect = false;
  bool moved = false;  // suspect for `confirmations` windows in a row
};

// Watches a calibrated network for moved cameras; not thread-safe.
class CameraMotionMonitor {
 public:
  // `placed` marks the cameras the calibration placed; the others are not watched.
  CameraMotionMonitor(std::vector<CameraModel> cameras, std::vector<bool> placed,
                      const CameraMotionOptions& options = {});

  // Measures the baseline of every pair on `sequences` (frames that match the calibration,
  // e.g. the end of its window). Pairs unmeasured there are not judged later.
  void SetBaseline(const std::vector<SilhouetteSequence>& sequences);
  // Judges a new window; one verdict per placed camera, in camera order.
  std::vector<CameraMotionVerdict> Check(const std::vector<SilhouetteSequence>& sequences);
  // Takes `camera`'s new model (after it was re-estimated) and measures the baselines of its
  // pairs again on `sequences`; its suspicion count starts over.
  void ReplaceCamera(size_t camera, const CameraModel& model,
                     const std::vector<SilhouetteSequence>& sequences);

  const std::vector<CameraModel>& cameras() const { return cameras_; }
  bool HasBaseline() const { return !baseline_.empty(); }

 private:
  double Baseline(size_t i, size_t j) const;

  std::vector<CameraModel> cameras_;
  std::vector<bool> placed_;
  CameraMotionOptions options_;
  std::vector<PairResidual> baseline_;
  std::vector<int> suspect_runs_;
};

}  // namespace silnet::aggregator

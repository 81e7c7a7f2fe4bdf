#pragma once
// The calibrate job, `silnet-aggregator calibrate <input> -o OUT`: pairs -> synchronisation
// -> calibration in one go. Writes into OUT:
//   pairs.yaml, matches/        the pairwise stage (as `pairs` writes them), unless reused
//   calibration.yaml            the calibrated cameras (DESIGN.md "Files")
//   calibration_summary.yaml    per camera placed (with its uncertainty) or why not;
//                               synchronisation edges; stages;
//                               pairwise checks; ground-truth errors when known
//   colmap/                     cameras.txt, images.txt, points3D.txt
//   report/                     report.html with plots/
// A dataset folder holding ground_truth.yaml (a simulated capture) is compared with it.

#include <filesystem>
#include <optional>

#include "aggregator/calibration/calibration_result.h"
#include "aggregator/calibration/ground_truth_comparison.h"
#include "aggregator/calibration/network_calibration.h"
#include "aggregator/pairwise/pairwise_job.h"

namespace silnet::aggregator {

// Settings of the job.
struct CalibrateJobConfig {
  std::filesystem::path input;  // session store, node recording or dataset folder
  std::filesystem::path output;
  PairwiseJobOptions pairwise;
  std::filesystem::path reuse_pairs;  // a `pairs` output folder to reuse instead of estimating
  std::filesystem::path intrinsics;   // calibration YAML with trusted K and dist (known intrinsics)
  CalibrationOptions calibration;
  int first_frame = 0;      // first frame index to use
  int max_frames = 0;       // 0 = all
  std::string mask_video;   // each camera folder's mask video, when the input is one
  std::string frame_video;  // each camera folder's colour video, when the input is one
  bool report = true;       // write report/ (HTML and plots)
  bool compare_ground_truth =
      true;  // when the input has ground_truth.yaml (or ground_truth names one)
  std::filesystem::path ground_truth;  // a calibration YAML to compare with; empty = the input's
};

// What the job produced.
struct CalibrateJobResult {
  PairwiseJobResult pairs;
  NetworkCalibration calibration;
  std::optional<CalibrationErrors> errors;  // against ground truth, when known
  double seconds = 0.0;
};

// Runs the job. Throws InputError for unreadable input, an intrinsics file missing a
// camera, or unwritable output; an uncalibratable network is a result, not an error.
CalibrateJobResult RunCalibrateJob(const CalibrateJobConfig& config, Progress* progress);

// Writes calibration_summary.yaml. Throws InputError if unwritable.
void WriteCalibrationSummary(const std::filesystem::path& path, const CalibrateJobResult& result);

}  // namespace silnet::aggregator

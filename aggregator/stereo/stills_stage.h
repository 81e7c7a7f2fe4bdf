#pragma once
// Stills on command as one stage, shared by `silnet-aggregator stills` and the live job
// (issue 19): ask the nodes of the calibration in use for a still each (still_collector.h),
// write what arrived as a stills folder with that calibration carried over to the stills'
// resolution (still_views.h), and build the stereo model from it (stereo_job.h). With a
// simulation's true stills folder, the calibration is first aligned to its cameras and the
// model scored against its surface. With `collect.background` the stills are of the empty
// scene instead: each node keeps its own (to segment its later full-resolution stills), and
// the stage writes them as <output>/<camera>/background.png (the stills folder's layout).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/calibration/ground_truth_comparison.h"
#include "aggregator/ingest/still_collector.h"
#include "aggregator/stereo/stereo_job.h"
#include "shared/geometry/camera_model.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// What the stage does.
struct StillsStageConfig {
  StillCollectorOptions collect;     // targets are set from `cameras` when empty
  std::vector<CameraModel> cameras;  // the calibration in use
  std::filesystem::path output;      // the stills folder; the model goes to <output>/stereo
  bool stereo = true;                // build the model
  // Simulation only: a true stills folder of the subject (silnet-sim stills --cameras-from:
  // calibration.yaml, gt_surface.ply).
  std::filesystem::path truth;
  int threads = 0;  // stereo threads (0 = all cores)
};

// What came of it; `failure` says why there is no model (empty when there is one, or when
// none was asked for).
struct StillsStageResult {
  StillCollection collection;
  size_t views = 0;                   // stills usable for stereo (backgrounds written)
  std::vector<std::string> warnings;  // stills left out and why
  std::optional<CalibrationErrors> calibration_vs_truth;
  std::optional<StereoJobResult> stereo;
  std::string failure;
};

// Runs the stage; `progress` (optional) reports the collection, then the stereo job, and may
// cancel. Throws InputError for unusable settings (no cameras, unreadable truth) and
// DdsError if DDS cannot start; writes <output>/stills.yaml in any case once collected.
StillsStageResult RunStillsStage(const StillsStageConfig& config, Progress* progress = nullptr);

}  // namespace silnet::aggregator

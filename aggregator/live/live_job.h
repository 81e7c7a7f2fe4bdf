#pragma once
// The live job, `silnet-aggregator live -o OUT`: the aggregator as the main job runs it. It
// ingests every node's streams into OUT/session (as `ingest` does); once every camera has
// streamed enough frames it calibrates and synchronises the network from them in the
// background (as `calibrate` does, into OUT/calibration), retrying on more frames if the
// motion seen so far was not enough; it publishes the calibration on DDS; it builds the
// visual hulls of frames that follow the calibration window as soon as they have arrived
// (OUT/hulls; one batch, or batch after batch until the streams end when continuous); and it keeps
// ingesting until the nodes are done — or, as a service, until it is stopped, recalibrating on
// request from the newest frames and publishing the new calibration. While it runs it watches for
// cameras that moved after the calibration and re-estimates them (camera_motion_watch.h),
// publishing the corrected calibration. Progress goes to the log as it happens; the result feeds
// the report (live_report.h).

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/calibration/calibrate_job.h"
#include "aggregator/hulls/hull_sequence_job.h"
#include "aggregator/ingest/ingest_service.h"
#include "aggregator/live/camera_motion_watch.h"
#include "aggregator/stereo/stills_stage.h"

namespace silnet::aggregator {

// Settings of the live job.
struct LiveJobOptions {
  std::filesystem::path output;
  dds::DomainConfig domain;
  int expected_cameras = 0;            // wait for this many cameras (0: those that show up)
  int calibrate_after_frames = 400;    // frames every camera must have streamed first
  int max_calibration_attempts = 3;    // each waits for 1.5x the frames of the one before
  int hull_gap_frames = 10;            // first hull frame: this long after the window
  int hull_frames = 30;                // reference frames to build hulls of (per batch)
  bool continuous_hulls = false;       // keep building batches of hull_frames as frames arrive
  std::filesystem::path ground_truth;  // a simulation's ground_truth.yaml to compare with
  bool publish = true;                 // publish the calibration on DDS
  double idle_exit_s = 5.0;            // once hulls are built, exit after this long without samples
  double give_up_s = 60.0;             // exit after this long without samples while waiting for
                                       // frames (a calibration or hull build runs to its end)
  bool serve = false;                  // run until stopped (idle_exit_s and give_up_s do not apply)
  CalibrateJobConfig calibrate;        // pairwise and calibration settings (input/output are set)
  HullSequenceOptions hulls;
  CameraMotionWatchOptions motion;  // window_frames 0 turns the watch off
  // Once the streams have ended, ask the nodes for stills and build the stereo model with the
  // calibration in use, into <output>/stills (stereo/stills_stage.h).
  bool stills = false;
  // Instead, as soon as a calibration is in use, ask for the stills of this reference instant
  // (seconds; each node takes its first frame at or after it, or its next frame if that has
  // passed) and build the model in the background while ingesting goes on. Negative: off.
  double stills_at_s = -1.0;
  double stills_timeout_s = 30.0;
  std::filesystem::path stills_truth;  // simulation: the true stills folder to score against
};

// What happened; `failure` says why a stage did not complete (empty when all did).
struct LiveJobResult {
  std::vector<CameraIngestStatus> cameras;
  IngestTotals ingest;
  std::optional<CalibrateJobResult> calibration;
  int calibration_frames = 0;  // frames per camera the calibration used
  int calibration_attempts = 0;
  int calibration_first_frame = 0;            // the window's first frame (later than 0 after a
                                              // recalibration on the newest frames)
  int recalibrations = 0;                     // done on request
  std::vector<CameraMoveEvent> camera_moves;  // cameras seen to move, and their re-estimates
  int motion_checks = 0;
  bool published = false;
  std::optional<HullSequenceResult> hulls;
  int hull_first_frame = 0;
  std::optional<StillsStageResult> stills;
  std::string failure;
  double seconds = 0.0;
};

// Runs the job until it is done, `stop()` returns true, or the streams stay silent for
// give_up_s while it waits for frames. Once the first calibration is done, `recalibrate()`
// returning true starts a new calibration on the newest calibrate_after_frames frames of every
// camera, published when it places every camera the last one did. `stills_asked()` returning
// true means a stills request waits in the output folder (service_control.h): the job takes
// those stills with the calibration in use (once there is one; one request at a time) into
// <output>/stills, answers the request, and as a service rewrites its report with the model.
// Throws InputError/DdsError if the store or DDS cannot be opened.
LiveJobResult RunLiveJob(
    const LiveJobOptions& options, const std::function<bool()>& stop,
    const std::function<bool()>& recalibrate = [] { return false; },
    const std::function<bool()>& stills_asked = [] { return false; });

}  // namespace silnet::aggregator

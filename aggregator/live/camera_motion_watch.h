#pragma once
// The live job's watch for cameras that moved after the calibration (a service feature):
// every `window_frames` new frames it measures each camera pair's epipolar residuals against
// the calibration in use (camera_motion_monitor.h); a camera reported moved gets a warning,
// and once `reestimate_frames` frames after the move have arrived it is re-estimated with
// the other cameras held (moved_camera_reestimation.h). All work runs in the background, one
// step at a time, on frames taken from the job's in-memory window when the step starts; the
// job polls, and keeps the frames from OldestNeeded on. Writes into the job's output folder:
//   camera_motion.yaml             every camera's residual against its baseline after each
//                                  check, and the moves seen so far
//   camera-moved-<id>-<frame>/calibration.yaml   the calibration after a re-estimate

#include <filesystem>
#include <functional>
#include <future>
#include <memory>
#include <opencv2/core/persistence.hpp>
#include <optional>
#include <string>
#include <vector>

#include "aggregator/calibration/camera_motion_monitor.h"
#include "aggregator/calibration/moved_camera_reestimation.h"
#include "shared/util/progress.h"

namespace silnet::aggregator {

// Settings of the watch.
struct CameraMotionWatchOptions {
  int window_frames = 60;       // frames per check (0: no watch)
  int reestimate_frames = 240;  // frames after a move a camera is re-estimated from
  int max_attempts = 3;         // re-estimates of one move before giving up on it
  CameraMotionOptions motion;
  MovedCameraOptions moved;
};

// One camera seen to move, and what became of it.
struct CameraMoveEvent {
  std::string camera_id;
  int detected_frame = 0;  // end of the window that confirmed the move
  int after_frame = 0;     // frames from here on follow the move
  double residual_px = 0.0;
  double baseline_px = 0.0;
  size_t pairs_jumped = 0;
  size_t pairs_measured = 0;
  int attempts = 0;
  bool reestimated = false;
  int reestimate_first_frame = 0;  // the frames it was re-estimated from start here
  double rms_px = 0.0;
  std::string reason;  // why it was not (yet) re-estimated
  // Against a simulation's ground truth (the camera as it was at reestimate_first_frame),
  // -1 when unknown: rotation error and centre error relative to the rig's size.
  double truth_rotation_deg = -1.0;
  double truth_center_rel = -1.0;
};

// Writes `events` as a sequence under `key` (camera_motion.yaml's `moves`,
// live_summary.yaml's `camera_moves`).
void WriteMoveEvents(cv::FileStorage& fs, const std::string& key,
                     const std::vector<CameraMoveEvent>& events);

// A camera whose model changed (to apply to the calibration in use and publish).
struct CameraUpdate {
  size_t camera = 0;
  CameraModel model;
  std::filesystem::path calibration_file;  // the whole calibration with it, as written
};

// Every camera's held frames [first, first + count), as sequences.
using FrameWindow = std::function<std::vector<SilhouetteSequence>(uint64_t first, uint64_t count)>;

// Watches one calibration at a time; used from one thread.
class CameraMotionWatch {
 public:
  // `frames` gives the frames to work on, `output` is the job's folder, `ground_truth` a
  // simulation's ground_truth.yaml (empty if none).
  CameraMotionWatch(const CameraMotionWatchOptions& options, FrameWindow frames,
                    std::filesystem::path output, std::filesystem::path ground_truth);
  ~CameraMotionWatch();

  // Starts watching `cameras` (placed where `placed`), calibrated from frames
  // [first, first + frames); a watch in progress is stopped first.
  void Start(const std::vector<CameraModel>& cameras, const std::vector<bool>& placed, int first,
             int frames);
  // Cancels and waits for the step in progress; the watch stays idle until Start.
  void Stop();
  // Finishes a completed step and launches the next one that frames [0, newest) of every
  // camera allow. Returns the update when a moved camera has just been re-estimated.
  std::optional<CameraUpdate> Poll(int newest);
  // The oldest frame the watch may still ask for while frames [0, newest) are held, or
  // nullopt while it is idle (what Start will ask for is up to the caller).
  std::optional<int> OldestNeeded(int newest) const;

  const std::vector<CameraMoveEvent>& events() const { return events_; }
  int checks() const { return checks_; }

 private:
  struct Step;
  void Launch(std::function<void(Step*)> work);
  std::optional<CameraUpdate> Finish(Step& step);
  // Rewrites OUT/camera_motion.yaml at once (the status command reads it while the job runs);
  // a file that cannot be written is a warning in the log.
  void WriteStatus() const;

  CameraMotionWatchOptions options_;
  FrameWindow frames_;
  std::filesystem::path output_, ground_truth_;
  std::unique_ptr<CameraMotionMonitor> monitor_;
  std::vector<CameraModel> cameras_;
  std::vector<bool> placed_;
  std::vector<bool> given_up_;
  int next_end_ = 0;               // end of the next window to check
  std::optional<size_t> pending_;  // event index of a move awaiting its re-estimate
  size_t pending_camera_ = 0;      // and its camera
  std::unique_ptr<Progress> progress_;
  std::future<std::unique_ptr<Step>> step_;
  std::vector<CameraMoveEvent> events_;
  std::vector<CameraMotionVerdict> last_verdicts_;
  int last_window_ = 0;
  int checks_ = 0;
};

}  // namespace silnet::aggregator

#include "aggregator/live/camera_motion_watch.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <opencv2/core/persistence.hpp>

#include "aggregator/calibration/ground_truth_comparison.h"
#include "shared/io/calibration_yaml.h"
#include "shared/io/replace_yaml.h"
#include "shared/util/check.h"

namespace silnet::aggregator {

// One background step and what it found.
struct CameraMotionWatch::Step {
  enum class Kind { kBaseline, kCheck, kReestimate } kind = Kind::kCheck;
  int first = 0;  // frames [first, first + count)
  int count = 0;
  size_t camera = 0;  // the camera re-estimated
  std::vector<CameraMotionVerdict> verdicts;
  std::optional<MovedCameraEstimate> estimate;
  std::string error;  // the frames could not be read
};

CameraMotionWatch::CameraMotionWatch(const CameraMotionWatchOptions& options, FrameWindow frames,
                                     std::filesystem::path output,
                                     std::filesystem::path ground_truth)
    : options_(options),
      frames_(std::move(frames)),
      output_(std::move(output)),
      ground_truth_(std::move(ground_truth)) {
  if (options_.window_frames < 0 || options_.reestimate_frames < 20 || options_.max_attempts < 1)
    throw InputError(
        "camera motion watch: the window must not be negative, a re-estimate needs at least 20 "
        "frames and one attempt");
  if (const std::string invalid = options_.motion.Validate(); !invalid.empty())
    throw InputError("camera motion watch: " + invalid);
}

CameraMotionWatch::~CameraMotionWatch() {
  Stop();
}

void CameraMotionWatch::Start(const std::vector<CameraModel>& cameras,
                              const std::vector<bool>& placed, int first, int frames) {
  Stop();
  if (options_.window_frames == 0) return;
  cameras_ = cameras;
  placed_ = placed;
  given_up_.assign(cameras.size(), false);
  pending_.reset();
  last_verdicts_.clear();
  monitor_ = std::make_unique<CameraMotionMonitor>(cameras, placed, options_.motion);
  const int end = first + frames;
  const int count = std::min(options_.window_frames, frames);
  next_end_ = end + options_.window_frames;
  Launch([this, end, count](Step* step) {
    step->kind = Step::Kind::kBaseline;
    step->first = end - count;
    step->count = count;
  });
}

void CameraMotionWatch::Stop() {
  if (progress_) progress_->Cancel();
  if (step_.valid()) step_.wait();
  step_ = {};
  monitor_.reset();
  pending_.reset();
}

void CameraMotionWatch::Launch(std::function<void(Step*)> setup) {
  auto step = std::make_unique<Step>();
  setup(step.get());
  progress_ = std::make_unique<Progress>("camera motion", 0, ConsoleProgressPrinter(),
                                         std::chrono::seconds(5));
  // The frames are taken now, before the holder may drop them.
  std::vector<SilhouetteSequence> sequences;
  try {
    sequences = frames_(static_cast<uint64_t>(step->first), static_cast<uint64_t>(step->count));
  } catch (const std::exception& e) {
    step->error = e.what();
  }
  step_ =
      std::async(std::launch::async, [this, monitor = monitor_.get(), progress = progress_.get(),
                                      cameras = cameras_, placed = placed_, step = std::move(step),
                                      sequences = std::move(sequences)]() mutable {
        if (!step->error.empty()) return std::move(step);
        try {
          switch (step->kind) {
            case Step::Kind::kBaseline:
              monitor->SetBaseline(sequences);
              break;
            case Step::Kind::kCheck:
              step->verdicts = monitor->Check(sequences);
              break;
            case Step::Kind::kReestimate:
              step->estimate = ReestimateMovedCamera(cameras, placed, step->camera, sequences,
                                                     options_.moved, progress);
              if (step->estimate->ok)
                monitor->ReplaceCamera(step->camera, step->estimate->camera, sequences);
              break;
          }
        } catch (const std::exception& e) {
          step->error = e.what();
        }
        return std::move(step);
      });
}

std::optional<int> CameraMotionWatch::OldestNeeded(int newest) const {
  if (!monitor_) return std::nullopt;
  // The baseline and the next check lie within two windows of next_end_.
  int oldest = next_end_ - 2 * options_.window_frames;
  if (pending_) oldest = std::min(oldest, newest - options_.reestimate_frames);
  return std::max(oldest, 0);
}

std::optional<CameraUpdate> CameraMotionWatch::Poll(int newest) {
  if (!monitor_) return std::nullopt;
  if (step_.valid()) {
    if (step_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return std::nullopt;
    const std::unique_ptr<Step> step = step_.get();
    return Finish(*step);
  }
  const int window = options_.window_frames;
  if (pending_) {
    const CameraMoveEvent& event = events_[*pending_];
    const int first = newest - options_.reestimate_frames;
    if (first < event.after_frame) return std::nullopt;
    const size_t camera = pending_camera_;
    spdlog::info("live: re-estimating {} from frames {}..{}, the other cameras held",
                 event.camera_id, first, newest - 1);
    Launch([&](Step* step) {
      step->kind = Step::Kind::kReestimate;
      step->first = first;
      step->count = options_.reestimate_frames;
      step->camera = camera;
    });
    return std::nullopt;
  }
  if (newest >= next_end_) {
    const int first = next_end_ - window;
    next_end_ += window;
    Launch([&](Step* step) {
      step->kind = Step::Kind::kCheck;
      step->first = first;
      step->count = window;
    });
  }
  return std::nullopt;
}

std::optional<CameraUpdate> CameraMotionWatch::Finish(Step& step) {
  if (!step.error.empty()) {
    spdlog::warn("live: camera motion watch: frames {}..{}: {}", step.first,
                 step.first + step.count - 1, step.error);
    return std::nullopt;
  }
  switch (step.kind) {
    case Step::Kind::kBaseline:
      spdlog::info("live: watching for moved cameras (checks every {} frames from frame {})",
                   options_.window_frames, next_end_ - options_.window_frames);
      return std::nullopt;
    case Step::Kind::kCheck:
      break;
    case Step::Kind::kReestimate: {
      CameraMoveEvent& event = events_[*pending_];
      const MovedCameraEstimate& estimate = *step.estimate;
      ++event.attempts;
      if (!estimate.ok) {
        event.reason = estimate.reason;
        if (event.attempts >= options_.max_attempts) {
          spdlog::error("live: {} could not be re-estimated ({}); giving up after {} attempts",
                        event.camera_id, event.reason, event.attempts);
          given_up_[step.camera] = true;
          pending_.reset();
        } else {
          event.after_frame = step.first + step.count;
          spdlog::warn("live: {} could not be re-estimated ({}); trying again on later frames",
                       event.camera_id, event.reason);
        }
        WriteStatus();
        return std::nullopt;
      }
      event.reestimated = true;
      event.reason.clear();
      event.reestimate_first_frame = step.first;
      event.rms_px = estimate.rms_px;
      cameras_[step.camera] = estimate.camera;
      pending_.reset();
      if (!ground_truth_.empty() && std::filesystem::exists(ground_truth_)) {
        const CalibrationErrors errors = CompareWithGroundTruth(
            cameras_, placed_, LoadCamerasAtFrame(ground_truth_, step.first));
        for (const CameraError& e : errors.cameras) {
          if (e.id != event.camera_id) continue;
          event.truth_rotation_deg = e.rotation_deg;
          event.truth_center_rel = e.center_rel;
        }
      }
      const std::filesystem::path folder =
          output_ / fmt::format("camera-moved-{}-{}", event.camera_id, event.detected_frame);
      std::filesystem::create_directories(folder);
      std::vector<CameraModel> placed_cameras;
      for (size_t c = 0; c < cameras_.size(); ++c) {
        if (placed_[c]) placed_cameras.push_back(cameras_[c]);
      }
      SaveCalibration(folder / "calibration.yaml", placed_cameras);
      spdlog::info("live: {} re-estimated from {} partners, {:.3f} px rms; written to {}",
                   event.camera_id, estimate.partners.size(), estimate.rms_px, folder.string());
      WriteStatus();
      return CameraUpdate{step.camera, estimate.camera, folder / "calibration.yaml"};
    }
  }
  ++checks_;
  last_verdicts_ = step.verdicts;
  last_window_ = step.first;
  for (const CameraMotionVerdict& v : step.verdicts) {
    if (v.suspect && !v.moved) {
      spdlog::warn(
          "live: {} may have moved: epipolar residual {:.2f} px against {:.2f} px before "
          "on {} of {} pairs (frames {}..{})",
          v.camera_id, v.residual_px, v.baseline_px, v.pairs_jumped, v.pairs_measured, step.first,
          step.first + step.count - 1);
    }
    if (!v.moved || given_up_[v.camera] || pending_) continue;
    CameraMoveEvent event;
    event.camera_id = v.camera_id;
    event.detected_frame = step.first + step.count;
    event.after_frame = event.detected_frame;
    event.residual_px = v.residual_px;
    event.baseline_px = v.baseline_px;
    event.pairs_jumped = v.pairs_jumped;
    event.pairs_measured = v.pairs_measured;
    events_.push_back(event);
    pending_ = events_.size() - 1;
    pending_camera_ = v.camera;
    spdlog::warn(
        "live: CAMERA MOVED: {}'s epipolar residuals rose from {:.2f} px to {:.2f} px on {} of "
        "{} pairs; it will be re-estimated once {} frames after frame {} have arrived",
        v.camera_id, v.baseline_px, v.residual_px, v.pairs_jumped, v.pairs_measured,
        options_.reestimate_frames, event.after_frame);
  }
  WriteStatus();
  return std::nullopt;
}

void CameraMotionWatch::WriteStatus() const {
  const std::filesystem::path path = output_ / "camera_motion.yaml";
  try {
    ReplaceYaml(path, [&](cv::FileStorage& fs) {
      fs << "checks" << checks_ << "last_window_first_frame" << last_window_ << "window_frames"
         << options_.window_frames;
      fs << "cameras"
         << "[";
      for (const CameraMotionVerdict& v : last_verdicts_) {
        fs << "{"
           << "id" << v.camera_id << "residual_px" << v.residual_px << "baseline_px"
           << v.baseline_px << "pairs_measured" << static_cast<int>(v.pairs_measured)
           << "pairs_jumped" << static_cast<int>(v.pairs_jumped) << "suspect"
           << static_cast<int>(v.suspect) << "moved" << static_cast<int>(v.moved) << "}";
      }
      fs << "]";
      WriteMoveEvents(fs, "moves", events_);
    });
  } catch (const InputError& e) {
    spdlog::warn("live: {}", e.what());
  }
}

void WriteMoveEvents(cv::FileStorage& fs, const std::string& key,
                     const std::vector<CameraMoveEvent>& events) {
  fs << key << "[";
  for (const CameraMoveEvent& e : events) {
    fs << "{"
       << "id" << e.camera_id << "detected_frame" << e.detected_frame << "after_frame"
       << e.after_frame << "residual_px" << e.residual_px << "baseline_px" << e.baseline_px
       << "pairs_jumped" << static_cast<int>(e.pairs_jumped) << "pairs_measured"
       << static_cast<int>(e.pairs_measured) << "attempts" << e.attempts << "reestimated"
       << static_cast<int>(e.reestimated) << "reestimate_first_frame" << e.reestimate_first_frame
       << "rms_px" << e.rms_px << "reason" << e.reason << "truth_rotation_deg"
       << e.truth_rotation_deg << "truth_center_rel" << e.truth_center_rel << "}";
  }
  fs << "]";
}

}  // namespace silnet::aggregator

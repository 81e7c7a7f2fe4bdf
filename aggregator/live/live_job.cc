#include "aggregator/live/live_job.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>

#include "aggregator/calibration/calibration_publisher.h"
#include "aggregator/ingest/still_views.h"
#include "aggregator/live/live_report.h"
#include "aggregator/live/recent_contours.h"
#include "aggregator/live/recent_silhouettes.h"
#include "aggregator/live/service_control.h"
#include "shared/io/calibration_yaml.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Frames 0..n-1 of a camera's newest session are all held: returns n (0 while a gap is open).
int StreamedFrames(const CameraIngestStatus& c) {
  if (c.frames_held == 0 || c.first_frame != 0 || c.missing != 0) return 0;
  return static_cast<int>(c.last_frame + 1);
}

int FewestStreamed(const std::vector<CameraIngestStatus>& cameras) {
  int fewest = std::numeric_limits<int>::max();
  for (const CameraIngestStatus& c : cameras)
    fewest = std::min(fewest, StreamedFrames(c));
  return cameras.empty() ? 0 : fewest;
}

enum class Stage {
  kCollecting,
  kCalibrating,
  kWaitingForHullFrames,
  kBuildingHulls,
  kDone,
  kRecalibrating
};

const char* ToString(Stage stage) {
  switch (stage) {
    case Stage::kCollecting:
      return "collecting frames for the calibration";
    case Stage::kCalibrating:
      return "calibrating";
    case Stage::kWaitingForHullFrames:
      return "waiting for the frames to build hulls from";
    case Stage::kBuildingHulls:
      return "building hulls";
    case Stage::kDone:
      return "done; ingesting";
    case Stage::kRecalibrating:
      return "recalibrating on the newest frames";
  }
  return "?";
}

// The job's state between polls.
class LiveJob {
 public:
  LiveJob(const LiveJobOptions& options, const std::function<bool()>& stop,
          const std::function<bool()>& recalibrate, const std::function<bool()>& stills_asked)
      : options_(options),
        stop_(stop),
        recalibrate_(recalibrate),
        stills_asked_(stills_asked),
        contours_(options.output / "session" / "sessions"),
        ingest_(IngestOptionsFor(options, &recent_, &contours_)),
        watch_(
            options.motion,
            [this](uint64_t first, uint64_t count) { return FrameWindow(first, count); },
            options.output,
            options.ground_truth.empty() ? std::filesystem::path()
                                         : options.output / "session" / "ground_truth.yaml"),
        calibration_frames_(options.calibrate_after_frames) {}

  LiveJobResult Run() {
    const auto start = started_;
    ingest_.Open();
    participant_ = std::make_unique<dds::Participant>(options_.domain);
    spdlog::info("live: ingesting into {} ({}); calibrating once every camera has {} frames",
                 (options_.output / "session").string(), options_.domain.Describe(),
                 calibration_frames_);
    auto last_activity = Clock::now();
    uint64_t last_received = 0;
    auto stage_entered = Clock::now();
    auto next_status = Clock::now() + std::chrono::seconds(5);
    while (!stop_()) {
      // Activity is frames arriving: nodes that linger after their feeds still send their
      // status every second, and the streams have ended all the same.
      ingest_.Poll(std::chrono::milliseconds(100));
      const std::vector<CameraIngestStatus> cameras = ingest_.Status();
      uint64_t received = 0;
      for (const CameraIngestStatus& c : cameras)
        received += c.received;
      if (received != last_received) {
        last_received = received;
        last_activity = Clock::now();
      }
      const double idle = SecondsSince(last_activity);
      if (Clock::now() >= next_status) {
        next_status = Clock::now() + std::chrono::seconds(5);
        LogStatus(cameras);
        // Every node's state (alive, fps, drops, newest frame) for tools watching the run.
        ingest_.WriteSummary(options_.output / "session" / "ingest_summary.yaml");
      }
      const Stage before = stage_;
      Advance(cameras, idle);
      AdvanceStills();
      WatchForMovedCameras(cameras);
      if (stage_ != before) stage_entered = Clock::now();
      if (options_.serve) continue;
      if (stage_ == Stage::kDone && idle > options_.idle_exit_s && ingest_.Totals().missing == 0 &&
          !StillsRunning()) {
        break;
      }
      // Silence ends the run only while it waits for frames (or for missing ones at the end);
      // a calibration or hull build in progress runs to its end on the frames that arrived,
      // and a wait that has just begun (after a long calibration) first looks at those.
      const bool waiting_for_frames = stage_ == Stage::kCollecting ||
                                      stage_ == Stage::kWaitingForHullFrames ||
                                      stage_ == Stage::kDone;
      const double silent = std::min(idle, SecondsSince(stage_entered));
      if (waiting_for_frames && silent > options_.give_up_s && ingest_.Totals().received > 0 &&
          !StillsRunning()) {
        spdlog::warn("live: no samples for {:.0f} s: stopping while {}", idle, ToString(stage_));
        if (result_.failure.empty())
          result_.failure = fmt::format("the streams went silent while {}", ToString(stage_));
        break;
      }
    }
    Cancel();
    AnswerOpenStillsRequests();
    watch_.Stop();
    result_.camera_moves = watch_.events();
    result_.motion_checks = watch_.checks();
    if (stop_() && result_.failure.empty() && stage_ != Stage::kDone &&
        stage_ != Stage::kRecalibrating)
      result_.failure = fmt::format("stopped while {}", ToString(stage_));
    ingest_.Flush();
    ingest_.WriteSummary(options_.output / "session" / "ingest_summary.yaml");
    if (options_.stills && options_.stills_at_s < 0 && !stop_()) TakeStills();
    result_.cameras = ingest_.Status();
    result_.ingest = ingest_.Totals();
    result_.seconds = SecondsSince(start);
    return std::move(result_);
  }

 private:
  static IngestOptions IngestOptionsFor(const LiveJobOptions& options, RecentSilhouettes* recent,
                                        RecentContours* contours) {
    IngestOptions ingest;
    ingest.store_dir = options.output / "session" / "sessions";
    ingest.domain = options.domain;
    // The camera motion watch works on the newest frames, held in memory.
    if (options.motion.window_frames > 0)
      ingest.on_hull_stored = [recent](const FrameRecord& record) { recent->Add(record); };
    // So do the hull batches, on the newest contours.
    if (options.hull_frames > 0)
      ingest.on_contour_stored = [contours](const FrameRecord& record) { contours->Add(record); };
    return ingest;
  }

  void LogStatus(const std::vector<CameraIngestStatus>& cameras) const {
    const IngestTotals totals = ingest_.Totals();
    int most = 0;
    for (const CameraIngestStatus& c : cameras)
      most = std::max(most, StreamedFrames(c));
    spdlog::info("live: {}; {} cameras, {}..{} frames each, {} missing, {} stalled",
                 ToString(stage_), cameras.size(), FewestStreamed(cameras), most, totals.missing,
                 totals.cameras_stalled);
  }

  void Advance(const std::vector<CameraIngestStatus>& cameras, double idle) {
    switch (stage_) {
      case Stage::kCollecting:
        if (ReadyToCalibrate(cameras)) StartCalibration();
        break;
      case Stage::kCalibrating:
        if (Ready(calibration_future_)) FinishCalibration(idle);
        break;
      case Stage::kWaitingForHullFrames:
        // Building hulls continuously, the job is between batches here: a recalibration
        // request is served now.
        if (HullsOngoing() && result_.calibration && recalibrate_()) {
          StartRecalibration(cameras);
        } else if (ReadyForHulls(cameras, idle)) {
          StartHulls();
        }
        break;
      case Stage::kBuildingHulls:
        if (Ready(hulls_future_)) FinishHulls();
        break;
      case Stage::kDone:
        if (result_.calibration && recalibrate_()) StartRecalibration(cameras);
        break;
      case Stage::kRecalibrating:
        if (Ready(calibration_future_)) FinishRecalibration();
        break;
    }
  }

  // Every camera's frames [first, first + count): from memory, or from the session store
  // for frames this run did not receive itself (stored before a restart).
  std::vector<SilhouetteSequence> FrameWindow(uint64_t first, uint64_t count) const {
    if (recent_.Holds(first)) return recent_.Window(first, count);
    SequenceLoadOptions load;
    load.first_frame = static_cast<int>(first);
    load.max_frames = static_cast<int>(count);
    return LoadSequences(options_.output / "session", load);
  }

  // Once a calibration is in use (and none is being computed), the watch checks the newest
  // frames; a re-estimated camera replaces its model in the calibration, which is published.
  void WatchForMovedCameras(const std::vector<CameraIngestStatus>& cameras) {
    if (!result_.calibration || stage_ == Stage::kCalibrating || stage_ == Stage::kRecalibrating)
      return;
    const int newest = FewestStreamed(cameras);
    if (const std::optional<int> oldest = watch_.OldestNeeded(newest))
      recent_.DropBefore(static_cast<uint64_t>(*oldest));
    const std::optional<CameraUpdate> update = watch_.Poll(newest);
    if (!update) return;
    NetworkCalibration& calibration = result_.calibration->calibration;
    calibration.cameras[update->camera] = update->model;
    UseForHulls(update->calibration_file);
    if (publisher_) {
      publisher_->Publish(calibration, NewCalibrationId());
      spdlog::info("live: calibration with {} re-estimated published", update->model.id);
    }
  }

  // A new calibration on the newest calibrate_after_frames frames every camera holds.
  void StartRecalibration(const std::vector<CameraIngestStatus>& cameras) {
    const int newest = FewestStreamed(cameras);
    const int frames = options_.calibrate_after_frames;
    if (newest < frames) {
      spdlog::warn("live: recalibration asked for, but only {} frames are held", newest);
      return;
    }
    const int first = newest - frames;
    spdlog::info("live: recalibrating on frames {}..{} of every camera", first, newest - 1);
    watch_.Stop();
    LaunchCalibration(first, frames);
    stage_ = Stage::kRecalibrating;
  }

  void FinishRecalibration() {
    stage_ = HullsOngoing() ? Stage::kWaitingForHullFrames : Stage::kDone;
    CalibrateJobResult calibration;
    const auto keep = [&](const std::string& why) {
      spdlog::error("live: {}; keeping the calibration in use", why);
      WatchCalibration(result_.calibration_first_frame, result_.calibration_frames);
    };
    try {
      calibration = calibration_future_.get();
    } catch (const std::exception& e) {
      keep(fmt::format("recalibration failed: {}", e.what()));
      return;
    }
    const size_t placed = calibration.calibration.PlacedCount();
    if (placed < result_.calibration->calibration.PlacedCount()) {
      keep(fmt::format("recalibration placed only {} cameras", placed));
      return;
    }
    ++result_.recalibrations;
    result_.calibration = std::move(calibration);
    result_.calibration_first_frame = recalibration_first_;
    result_.calibration_frames = options_.calibrate_after_frames;
    spdlog::info("live: recalibrated: {} cameras, reprojection rms {:.3f} px", placed,
                 result_.calibration->calibration.rms_px);
    WatchCalibration(recalibration_first_, options_.calibrate_after_frames);
    UseForHulls(options_.output / ("recalibration-" + std::to_string(recalibration_first_)) /
                "calibration.yaml");
    if (publisher_) {
      publisher_->Publish(result_.calibration->calibration, NewCalibrationId());
      spdlog::info("live: new calibration published");
    }
  }

  // Watches the calibration in use, calibrated from frames [first, first + frames).
  void WatchCalibration(int first, int frames) {
    const NetworkCalibration& c = result_.calibration->calibration;
    watch_.Start(c.cameras, c.PlacedMask(), first, frames);
  }

  template <class T>
  static bool Ready(const std::future<T>& future) {
    return future.valid() && future.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  }

  bool ReadyToCalibrate(const std::vector<CameraIngestStatus>& cameras) {
    if (cameras.size() != camera_count_) {
      camera_count_ = cameras.size();
      cameras_changed_ = Clock::now();
    }
    const bool all_here = options_.expected_cameras > 0
                              ? static_cast<int>(cameras.size()) >= options_.expected_cameras
                              : cameras.size() >= 2 && SecondsSince(cameras_changed_) > 3.0;
    return all_here && FewestStreamed(cameras) >= calibration_frames_;
  }

  void StartCalibration() {
    ++result_.calibration_attempts;
    if (!options_.ground_truth.empty()) {
      std::filesystem::copy_file(options_.ground_truth,
                                 options_.output / "session" / "ground_truth.yaml",
                                 std::filesystem::copy_options::overwrite_existing);
    }
    spdlog::info("live: calibrating from the first {} frames of every camera (attempt {})",
                 calibration_frames_, result_.calibration_attempts);
    LaunchCalibration(0, calibration_frames_);
    stage_ = Stage::kCalibrating;
  }

  // Runs the calibrate job in the background on frames [first, first + frames) of the
  // session store; a recalibration writes to OUT/recalibration-<first>.
  void LaunchCalibration(int first, int frames) {
    CalibrateJobConfig config = options_.calibrate;
    config.input = options_.output / "session";
    config.output = first == 0 ? options_.output / "calibration"
                               : options_.output / ("recalibration-" + std::to_string(first));
    config.first_frame = first;
    config.max_frames = frames;
    recalibration_first_ = first;
    // The motion watch's baseline will be the window's last frames; older ones can go.
    recent_.DropBefore(
        static_cast<uint64_t>(std::max(0, first + frames - options_.motion.window_frames)));
    progress_ = std::make_unique<Progress>("calibrate", 0, ConsoleProgressPrinter(),
                                           std::chrono::seconds(5));
    Progress* progress = progress_.get();
    calibration_future_ = std::async(
        std::launch::async, [config, progress] { return RunCalibrateJob(config, progress); });
  }

  void FinishCalibration(double idle) {
    CalibrateJobResult calibration;
    try {
      calibration = calibration_future_.get();
    } catch (const std::exception& e) {
      Fail(fmt::format("calibration failed: {}", e.what()));
      return;
    }
    const size_t placed = calibration.calibration.PlacedCount();
    const bool complete = placed == calibration.calibration.cameras.size();
    const bool more_frames_may_come = idle < options_.idle_exit_s;
    if (!complete && result_.calibration_attempts < options_.max_calibration_attempts &&
        more_frames_may_come) {
      calibration_frames_ = calibration_frames_ * 3 / 2;
      spdlog::warn(
          "live: {} of {} cameras calibrated from the motion seen so far; trying again on {} "
          "frames",
          placed, calibration.calibration.cameras.size(), calibration_frames_);
      stage_ = Stage::kCollecting;
      return;
    }
    result_.calibration_frames = calibration_frames_;
    result_.calibration = std::move(calibration);
    if (placed < 2) {
      Fail(fmt::format("only {} camera(s) could be calibrated", placed));
      return;
    }
    spdlog::info("live: {} of {} cameras calibrated, reprojection rms {:.3f} px", placed,
                 result_.calibration->calibration.cameras.size(),
                 result_.calibration->calibration.rms_px);
    if (options_.publish) {
      publisher_ = std::make_unique<CalibrationPublisher>(*participant_);
      publisher_->Publish(result_.calibration->calibration, NewCalibrationId());
      result_.published = true;
      spdlog::info("live: calibration published on {}", options_.domain.Describe());
    }
    WatchCalibration(0, calibration_frames_);
    UseForHulls(options_.output / "calibration" / "calibration.yaml");
    result_.hull_first_frame = calibration_frames_ + options_.hull_gap_frames;
    hull_next_ = result_.hull_first_frame;
    hull_count_ = options_.hull_frames;
    stage_ = hull_count_ > 0 ? Stage::kWaitingForHullFrames : Stage::kDone;
  }

  // The stills stage with the calibration in use; `instant_s` >= 0 names the reference
  // instant of the stills (else each node's next frame).
  StillsStageConfig StillsConfig(double instant_s, bool stereo = true,
                                 bool background = false) const {
    StillsStageConfig config;
    config.stereo = stereo;
    config.collect.background = background;
    config.cameras = hull_cameras_;
    config.output = options_.output / (background ? "backgrounds" : "stills");
    config.truth = options_.stills_truth;
    config.collect.domain = options_.domain;
    config.collect.timeout =
        std::chrono::milliseconds(static_cast<int64_t>(options_.stills_timeout_s * 1000));
    for (const CameraModel& camera : hull_cameras_) {
      config.collect.targets.push_back(
          StillTarget{camera.id, instant_s >= 0 ? FirstFrameAtOrAfter(camera, instant_s) : 0});
    }
    return config;
  }

  // Keeps the stage's outcome and its warnings; its failure fails the job unless a service
  // request asked for the stills (its asker is told instead).
  void KeepStills(StillsStageResult stills, bool requested = false) {
    for (const std::string& warning : stills.warnings)
      spdlog::warn("live: {}", warning);
    if (!requested && !stills.failure.empty() && result_.failure.empty())
      result_.failure = "stills: " + stills.failure;
    result_.stills = std::move(stills);
  }

  // Once the streams have ended: asks the nodes for stills and builds the stereo model.
  void TakeStills() {
    if (hull_cameras_.empty()) {
      spdlog::warn("live: no calibration, so no stills");
      return;
    }
    spdlog::info("live: asking the {} calibrated cameras for stills", hull_cameras_.size());
    Progress progress("stills", 0, ConsoleProgressPrinter(), std::chrono::seconds(5));
    try {
      KeepStills(RunStillsStage(StillsConfig(-1.0), &progress));
    } catch (const std::exception& e) {
      if (result_.failure.empty()) result_.failure = fmt::format("stills failed: {}", e.what());
    }
  }

  // Starts the stills stage in the background; `request` names the service request it
  // answers (empty for --stills-at).
  void StartStills(const StillsStageConfig& config, const std::string& request) {
    stills_request_ = request;
    stills_progress_ =
        std::make_unique<Progress>("stills", 0, ConsoleProgressPrinter(), std::chrono::seconds(5));
    stills_future_ = std::async(std::launch::async, [config, progress = stills_progress_.get()] {
      return RunStillsStage(config, progress);
    });
  }

  // Stills of an instant (--stills-at) once a calibration is in use, stills asked for by the
  // service command (one stage at a time, the newest request waiting for a running one), and
  // the outcome of a stage that has finished: kept for the report, answered to the asker, and
  // in the report at once when the job runs as a service.
  void AdvanceStills() {
    if (stills_asked_()) TakeNewStillsRequest();
    if (options_.stills_at_s >= 0 && !stills_started_ && !hull_cameras_.empty() &&
        !StillsRunning()) {
      stills_started_ = true;
      spdlog::info("live: asking the {} calibrated cameras for stills of {:.2f} s",
                   hull_cameras_.size(), options_.stills_at_s);
      StartStills(StillsConfig(options_.stills_at_s), "");
    }
    if (pending_stills_ && !StillsRunning() && !hull_cameras_.empty()) {
      const StillsRequest request = *std::exchange(pending_stills_, std::nullopt);
      spdlog::info("live: stills asked for: asking the {} calibrated cameras{}",
                   hull_cameras_.size(),
                   request.at_s >= 0 ? fmt::format(" for stills of {:.2f} s", request.at_s) : "");
      const StillsStageConfig config =
          StillsConfig(request.at_s, request.stereo, request.background);
      std::error_code ignored;
      std::filesystem::remove_all(config.output, ignored);
      StartStills(config, request.id);
      stills_background_ = request.background;
      Answer(request.id, "running",
             fmt::format("collecting the stills{} into {}\n",
                         request.background ? " of the empty scene" : "", config.output.string()));
    }
    if (!Ready(stills_future_)) return;
    const std::string request = std::exchange(stills_request_, std::string());
    if (std::exchange(stills_background_, false)) {
      AnswerBackgrounds(request);
      return;
    }
    try {
      KeepStills(stills_future_.get(), !request.empty());
    } catch (const std::exception& e) {
      if (request.empty() && result_.failure.empty())
        result_.failure = fmt::format("stills failed: {}", e.what());
      if (!request.empty()) Answer(request, "failed", fmt::format("stills failed: {}\n", e.what()));
      return;
    }
    if (options_.serve) {
      try {
        WriteLiveReport(options_.output, Snapshot());
      } catch (const InputError& e) {
        spdlog::warn("live: cannot rewrite the report with the stills: {}", e.what());
      }
    }
    if (!request.empty()) {
      const bool failed = !result_.stills->failure.empty();
      Answer(request, failed ? "failed" : "done", StillsSummary(*result_.stills));
    }
  }

  // Answers a finished request for stills of the empty scene (they stay out of the report).
  void AnswerBackgrounds(const std::string& request) {
    try {
      const StillsStageResult backgrounds = stills_future_.get();
      for (const std::string& warning : backgrounds.warnings)
        spdlog::warn("live: {}", warning);
      Answer(request, backgrounds.failure.empty() ? "done" : "failed",
             fmt::format("  empty scene  {} of {} cameras, in {}\n{}", backgrounds.views,
                         backgrounds.collection.cameras.size(),
                         (options_.output / "backgrounds").string(),
                         backgrounds.failure.empty() ? "" : backgrounds.failure + "\n"));
    } catch (const std::exception& e) {
      Answer(request, "failed", fmt::format("stills of the empty scene failed: {}\n", e.what()));
    }
  }

  // Reads a request the service command left; a newer one replaces one still waiting.
  void TakeNewStillsRequest() {
    std::optional<StillsRequest> request = TakeStillsRequest(options_.output);
    if (!request) return;
    if (pending_stills_)
      Answer(pending_stills_->id, "failed", "replaced by a later request before it started\n");
    pending_stills_ = std::move(request);
    if (hull_cameras_.empty() || StillsRunning()) {
      Answer(pending_stills_->id, "waiting",
             hull_cameras_.empty() ? "waiting for the first calibration\n"
                                   : "waiting for the stills being taken to be done\n");
    }
  }

  // Tells the asker of `request` where it stands (a failure to write is logged: the job goes on).
  void Answer(const std::string& request, const std::string& state, const std::string& text) {
    try {
      WriteStillsAnswer(options_.output, StillsAnswer{request, state, text});
    } catch (const InputError& e) {
      spdlog::warn("live: cannot answer stills request {}: {}", request, e.what());
    }
  }

  // The job is ending: requests not done are answered as such.
  void AnswerOpenStillsRequests() {
    if (!stills_request_.empty())
      Answer(stills_request_, "failed", "the live job stopped before the stills were done\n");
    if (pending_stills_)
      Answer(pending_stills_->id, "failed", "the live job stopped before taking the stills\n");
  }

  // The result so far, for a report while the job goes on.
  LiveJobResult Snapshot() const {
    LiveJobResult snapshot = result_;
    snapshot.cameras = ingest_.Status();
    snapshot.ingest = ingest_.Totals();
    snapshot.seconds = SecondsSince(started_);
    return snapshot;
  }

  // Stills asked for at an instant are being collected or reconstructed.
  bool StillsRunning() const { return stills_future_.valid(); }

  // Hulls from now on use the calibration in `file`.
  void UseForHulls(const std::filesystem::path& file) {
    hull_calibration_ = file;
    hull_cameras_ = LoadCalibration(file);
  }

  // Hulls are built batch after batch and the streams have not ended.
  bool HullsOngoing() const {
    return options_.continuous_hulls && options_.hull_frames > 0 && !hulls_ended_;
  }

  // The last frame of `camera` the hull of reference frame `frame` needs (the next one too
  // for sub-frame interpolation).
  int NeededFrame(const CameraModel& camera, int frame) const {
    const CameraModel& reference = hull_cameras_[ReferenceCameraIndex(hull_cameras_)];
    return static_cast<int>(std::ceil(camera.FrameAt(reference.ExposureTime(frame)))) + 1;
  }

  // The first frame of `camera` the hull of reference frame `frame` needs (the one before
  // too, whether the frame is interpolated or the nearest is taken).
  uint64_t FirstNeededFrame(const CameraModel& camera, int frame) const {
    const CameraModel& reference = hull_cameras_[ReferenceCameraIndex(hull_cameras_)];
    const double first = std::floor(camera.FrameAt(reference.ExposureTime(frame))) - 1;
    return first > 0 ? static_cast<uint64_t>(first) : 0;
  }

  // True if every calibrated camera's contours the next batch needs are held in memory.
  bool ContoursInMemory() const {
    return std::all_of(hull_cameras_.begin(), hull_cameras_.end(), [&](const CameraModel& c) {
      return contours_.Holds(c.id, FirstNeededFrame(c, hull_next_));
    });
  }

  // Reference frames [first, first + n) can be built once every calibrated camera holds the
  // frames they need with their contours; if the streams end first, fewer frames are built.
  bool ReadyForHulls(const std::vector<CameraIngestStatus>& cameras, double idle) {
    auto have = [&](int n) {
      const int last = hull_next_ + n - 1;
      for (const CameraModel& camera : hull_cameras_) {
        auto it = std::find_if(cameras.begin(), cameras.end(), [&](const CameraIngestStatus& c) {
          return c.camera_id == camera.id;
        });
        if (it == cameras.end() || StreamedFrames(*it) <= NeededFrame(camera, last)) return false;
      }
      return true;
    };
    if (ingest_.Totals().contours_overdue > 0) return false;
    if (have(hull_count_)) return true;
    if (idle < options_.idle_exit_s) return false;
    // The streams ended: build what arrived.
    while (hull_count_ > 0 && !have(hull_count_))
      --hull_count_;
    if (hull_count_ == 0) {
      hull_count_ = options_.hull_frames;
      if (!result_.hulls) {
        Fail("the streams ended before any frame after the calibration window arrived");
      } else if (!options_.serve) {
        // Continuous hulls: every frame that arrived has its hull.
        hulls_ended_ = true;
        stage_ = Stage::kDone;
      }
      return false;
    }
    spdlog::warn("live: the streams ended; building hulls of {} frames instead of {}", hull_count_,
                 options_.hull_frames);
    return true;
  }

  void StartHulls() {
    HullSequenceConfig config;
    config.input = options_.output / "session";
    config.calibration = hull_calibration_;
    config.output = options_.output / "hulls";
    config.first_frame = hull_next_;
    config.last_frame = hull_next_ + hull_count_;
    config.options = options_.hulls;
    // Later batches keep the first batch's voxel size.
    if (result_.hulls) config.options.voxel_size = result_.hulls->voxel_size;
    hull_config_ = config;
    // Contours received by this run are read from memory; after a restart of the aggregator
    // the first batches may need contours stored before it, read from the session logs.
    const bool in_memory = ContoursInMemory();
    spdlog::info("live: building the hulls of frames {}..{} (contours from {})", config.first_frame,
                 config.last_frame - 1, in_memory ? "memory" : "the session logs");
    progress_ =
        std::make_unique<Progress>("hulls", 0, ConsoleProgressPrinter(), std::chrono::seconds(5));
    Progress* progress = progress_.get();
    const RecentContours* contours = in_memory ? &contours_ : nullptr;
    hulls_future_ = std::async(std::launch::async, [config, progress, contours] {
      return contours ? RunHullSequenceJob(config, *contours, progress)
                      : RunHullSequenceJob(config, progress);
    });
    stage_ = Stage::kBuildingHulls;
  }

  void FinishHulls() {
    stage_ = Stage::kDone;
    try {
      HullSequenceResult batch = hulls_future_.get();
      spdlog::info("live: {} of {} hulls built, mean missed {:.2f} % of silhouette pixels",
                   batch.Succeeded(), batch.frames.size(), 100 * batch.MeanMissed());
      if (!result_.hulls) {
        result_.hulls = std::move(batch);
      } else {
        // One index for every batch.
        auto& frames = result_.hulls->frames;
        frames.insert(frames.end(), batch.frames.begin(), batch.frames.end());
        result_.hulls->seconds += batch.seconds;
        WriteHullIndex(hull_config_, *result_.hulls);
      }
    } catch (const std::exception& e) {
      result_.failure = fmt::format("hulls failed: {}", e.what());
      spdlog::error("live: {}", result_.failure);
      return;
    }
    hull_next_ += hull_count_;
    hull_count_ = options_.hull_frames;
    if (!HullsOngoing()) {
      contours_.Close();
      return;
    }
    for (const CameraModel& camera : hull_cameras_)
      contours_.DropBefore(camera.id, FirstNeededFrame(camera, hull_next_));
    stage_ = Stage::kWaitingForHullFrames;
  }

  void Fail(const std::string& why) {
    result_.failure = why;
    spdlog::error("live: {}", why);
    stage_ = Stage::kDone;
  }

  // Cancels and waits for a background stage still running.
  void Cancel() {
    if (progress_ && (calibration_future_.valid() || hulls_future_.valid())) progress_->Cancel();
    if (stills_progress_ && stills_future_.valid()) stills_progress_->Cancel();
    try {
      if (calibration_future_.valid()) calibration_future_.get();
      if (hulls_future_.valid()) hulls_future_.get();
      if (stills_future_.valid()) stills_future_.get();
    } catch (const std::exception& e) {
      spdlog::warn("live: a cancelled stage ended with: {}", e.what());
    }
  }

  const LiveJobOptions& options_;
  std::function<bool()> stop_;
  std::function<bool()> recalibrate_;
  std::function<bool()> stills_asked_;
  Clock::time_point started_ = Clock::now();
  int recalibration_first_ = 0;
  RecentSilhouettes recent_;  // before ingest_, which feeds it
  RecentContours contours_;   // the same; outlives the hull batch reading it
  IngestService ingest_;
  CameraMotionWatch watch_;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<CalibrationPublisher> publisher_;
  Stage stage_ = Stage::kCollecting;
  size_t camera_count_ = 0;
  Clock::time_point cameras_changed_ = Clock::now();
  int calibration_frames_;
  int hull_count_ = 0;  // frames in the next batch
  int hull_next_ = 0;   // first frame of the next batch
  bool hulls_ended_ = false;
  std::filesystem::path hull_calibration_;
  HullSequenceConfig hull_config_;  // of the batch last started
  std::vector<CameraModel> hull_cameras_;
  std::unique_ptr<Progress> progress_;
  std::future<CalibrateJobResult> calibration_future_;
  std::future<HullSequenceResult> hulls_future_;
  bool stills_started_ = false;
  std::optional<StillsRequest> pending_stills_;  // asked for by the service command
  std::string stills_request_;      // the request the running stage answers ("" for --stills-at)
  bool stills_background_ = false;  // the running stage takes stills of the empty scene
  std::unique_ptr<Progress> stills_progress_;
  std::future<StillsStageResult> stills_future_;
  LiveJobResult result_;
};

}  // namespace

LiveJobResult RunLiveJob(const LiveJobOptions& options, const std::function<bool()>& stop,
                         const std::function<bool()>& recalibrate,
                         const std::function<bool()>& stills_asked) {
  if (options.calibrate_after_frames < 10)
    throw InputError("the calibration needs at least 10 frames per camera");
  if (options.hull_frames < 0) throw InputError("the number of hull frames must not be negative");
  std::filesystem::create_directories(options.output);
  LiveJob job(options, stop, recalibrate, stills_asked);
  return job.Run();
}

}  // namespace silnet::aggregator

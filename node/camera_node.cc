#include "node/camera_node.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>

#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <thread>

#include "node/publish/frame_history.h"
#include "node/publish/frame_recorder.h"
#include "node/publish/still_store.h"
#include "node/segmentation/background_difference.h"
#include "shared/dds/still_command.h"
#include "shared/io/session_log_reader.h"
#include "shared/util/bounded_queue.h"

namespace silnet::node {
namespace {

using Clock = std::chrono::steady_clock;

constexpr uint32_t kProblemFlags = silnet_wire_FRAME_EMPTY | silnet_wire_FRAME_SATURATED |
                                   silnet_wire_FRAME_BAD_INPUT | silnet_wire_FRAME_DROPPED |
                                   silnet_wire_FRAME_WARMUP;

double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

std::string HostName() {
  char name[256] = {};
  gethostname(name, sizeof(name) - 1);
  return name;
}

}  // namespace

const char* NodeVersion() {
  return "0.1.0";
}

std::string CameraNodeOptions::Validate() const {
  if (processing.camera_id.empty()) return "a camera id is required";
  if (processing.camera_id.size() > 31) return "camera ids are at most 31 characters";
  if (processing_queue < 1 || publish_queue < 16) return "queues are too small";
  if (status_period < std::chrono::milliseconds(50)) return "status period below 50 ms";
  return processing.segmentation.Validate();
}

// What a still sends: its photo, silhouette and the silhouette's FrameFlags.
struct StillPicture {
  cv::Mat photo, silhouette;
  uint32_t flags = 0;
};

struct CameraNode::State {
  struct CaptureJob {
    CapturedFrame frame;
    uint32_t flags = 0;    // non-zero: publish flagged, do not process
    bool discard = false;  // captured while stopped
  };
  struct PublishJob {
    FrameRecord hull;
    std::optional<FrameRecord> contour;
    bool resent = false;
  };
  // A still to encode and send (photo non-empty), or chunks of a held one to send again.
  struct StillJob {
    uint64_t still_id = 0;
    bool background = false;  // of the empty scene: kept to segment later stills
    uint64_t frame_index = 0;
    uint32_t frame_flags = 0;
    int64_t capture_time_ns = 0;
    cv::Mat photo, silhouette;
    std::optional<silnet_wire_StillPart> part;  // resend: this part only (else both)
    uint32_t first_chunk = 0, last_chunk = UINT32_MAX;
  };

  CameraNodeOptions options;
  std::unique_ptr<CaptureSource> source;
  CaptureFormat format;
  std::mutex processor_mutex;
  std::unique_ptr<FrameProcessor> processor;
  std::unique_ptr<NodeTransport> transport;
  FrameHistory history;
  std::mutex recorder_mutex;
  std::unique_ptr<FrameRecorder> recorder;
  BoundedQueue<CaptureJob> processing_queue;
  BoundedQueue<PublishJob> publish_queue;
  StillRequests still_requests;
  StillStore still_store;
  std::mutex background_mutex;
  std::set<uint64_t> background_ids;  // requested stills of the empty scene
  cv::Mat still_background;           // the last one taken (the source's still size)
  BoundedQueue<StillJob> still_queue{64};
  std::mutex info_mutex;
  CameraInfoRecord info;
  std::mutex latest_mutex;  // the newest processed frame with its silhouette, for stills
  CapturedFrame latest_frame;
  cv::Mat latest_mask;
  uint32_t latest_flags = 0;
  std::mutex error_mutex;
  std::string last_error;

  std::atomic<bool> stopped{false};       // COMMAND_STOP
  std::atomic<bool> stop_capture{false};  // shutting down: capture no more
  std::atomic<bool> halt{false};          // shutting down: stop everything now
  std::atomic<bool> source_ended{false}, processing_done{false}, publishing_done{false};
  std::atomic<int64_t> last_captured_index{-1};  // newest frame index the source delivered
  std::atomic<uint64_t> captured{0}, processed{0}, published{0}, dropped{0}, flagged{0}, resent{0},
      commands{0}, capture_errors{0}, stills{0}, still_chunks_resent{0};

  State(CameraNodeOptions o, std::unique_ptr<CaptureSource> s)
      : options(std::move(o)),
        source(std::move(s)),
        history(options.history_frames),
        processing_queue(options.processing_queue),
        publish_queue(options.publish_queue) {
    stopped = options.start_stopped;
  }

  void SetError(const std::string& message) {
    std::lock_guard lock(error_mutex);
    last_error = message;
  }

  void CaptureLoop();
  void ProcessingLoop();
  void PublishingLoop();
  void ControlLoop();
  void StillLoop();
  StillPicture PictureOf(const StillJob& job);
  void SendStill(const StillJob& job);
  void ResendStill(const StillJob& job);
  void QueueStills(const std::vector<uint64_t>& ids, const CapturedFrame& frame,
                   const cv::Mat& silhouette, uint32_t flags);
  void AnswerStillsAfterTheEnd();
  void Emit(ProcessedFrame frame);
  void EmitDropped(uint64_t from, uint64_t to, int64_t last_time_ns, double period_ns);
  void Record(SessionRecordType type, const std::vector<uint8_t>& payload);
  void HandleCommand(const silnet_wire_Command& command);
  void ResendFromRecording(const silnet_wire_Command& command);
  silnet_wire_NodeStatus Status(double fps, double cpu_percent, const std::string& state);
  void PublishInfo();
};

void CameraNode::State::CaptureLoop() {
  auto last_warning = Clock::now() - std::chrono::hours(1);
  while (!stop_capture && !halt) {
    CaptureJob job;
    const CaptureStatus status = source->Read(&job.frame, std::chrono::milliseconds(200));
    if (status == CaptureStatus::kTimeout) continue;
    if (status == CaptureStatus::kEndOfStream) {
      spdlog::info("{}: end of stream after {} frames", source->Describe(), captured.load());
      source_ended = true;
      break;
    }
    if (status == CaptureStatus::kError) {
      ++capture_errors;
      SetError(source->LastError());
      if (Clock::now() - last_warning > std::chrono::seconds(5)) {
        spdlog::warn("capture: {}", source->LastError());
        last_warning = Clock::now();
      }
      continue;
    }
    ++captured;
    last_captured_index = static_cast<int64_t>(job.frame.frame_index);
    if (status == CaptureStatus::kFrameError) {
      ++capture_errors;
      job.flags = silnet_wire_FRAME_BAD_INPUT;
      SetError(source->LastError());
    }
    job.discard = stopped.load();
    // Never wait (unless lossless): a frame that finds the queue full is lost here and
    // published flagged by the processing thread when it sees the gap in frame indices.
    if (options.lossless)
      processing_queue.Push(std::move(job));
    else
      processing_queue.TryPush(std::move(job));
  }
  processing_queue.Close();
}

void CameraNode::State::Emit(ProcessedFrame frame) {
  if (frame.hull.flags & kProblemFlags) ++flagged;
  Record(SessionRecordType::kHullFrame, SerializeFrameRecord(frame.hull));
  if (frame.contour) Record(SessionRecordType::kContour, SerializeFrameRecord(*frame.contour));
  history.Add(HistoryEntry{frame.hull, frame.contour});
  publish_queue.Push(PublishJob{std::move(frame.hull), std::move(frame.contour), false});
}

void CameraNode::State::Record(SessionRecordType type, const std::vector<uint8_t>& payload) {
  std::lock_guard lock(recorder_mutex);
  if (recorder) recorder->Add(type, payload);
}

void CameraNode::State::ProcessingLoop() {
  bool first = true;
  uint64_t next_index = 0;
  int64_t last_time_ns = 0;
  const double period_ns = format.fps > 0 ? 1e9 / format.fps : 0.0;
  while (!halt) {
    std::optional<CaptureJob> job = processing_queue.Pop(std::chrono::milliseconds(100));
    if (!job) {
      if (processing_queue.closed()) break;
      continue;
    }
    const uint64_t index = job->frame.frame_index;
    if (first) {
      next_index = index;
      first = false;
    }
    if (index < next_index) {
      spdlog::warn("frame {} arrived after frame {}: ignored", index, next_index - 1);
      continue;
    }
    if (job->discard) {
      next_index = index + 1;
      continue;
    }
    // Frames lost between capture and here, or by the device, are published flagged.
    EmitDropped(next_index, index, last_time_ns, period_ns);
    ProcessedFrame result;
    {
      std::lock_guard lock(processor_mutex);
      result = job->flags != 0 ? processor->Flagged(index, job->frame.capture_time_ns, job->flags)
                               : processor->Process(job->frame);
    }
    if (!job->frame.image.empty()) {
      if (!result.mask.empty()) {
        std::lock_guard lock(latest_mutex);
        latest_frame = job->frame;
        latest_mask = result.mask;
        latest_flags = result.hull.flags;
      }
      ++processed;
      if (still_requests.waiting() > 0 && !result.mask.empty()) {
        QueueStills(still_requests.TakeDue(index), job->frame, result.mask, result.hull.flags);
      }
    }
    last_time_ns = job->frame.capture_time_ns;
    next_index = index + 1;
    Emit(std::move(result));
  }
  // Frames lost at the very end (the queue was full and no later frame shows the gap).
  const int64_t last = last_captured_index.load();
  if (!first && last >= 0 && static_cast<uint64_t>(last) >= next_index) {
    EmitDropped(next_index, static_cast<uint64_t>(last) + 1, last_time_ns, period_ns);
  }
  processing_done = true;
}

// Publishes frames [from, to) flagged FRAME_DROPPED, their capture times extrapolated from
// the last frame processed.
void CameraNode::State::EmitDropped(uint64_t from, uint64_t to, int64_t last_time_ns,
                                    double period_ns) {
  for (uint64_t missing = from; missing < to && !halt; ++missing) {
    const int64_t estimate =
        last_time_ns > 0
            ? last_time_ns +
                  static_cast<int64_t>(period_ns * static_cast<double>(missing - from + 1))
            : 0;
    ++dropped;
    Emit(processor->Flagged(missing, estimate, silnet_wire_FRAME_DROPPED));
  }
}

// Publishes frames as processing emits them and re-sends on request until halted: once
// processing is done and the queue drained, publishing_done says so but the loop stays to
// serve resend requests while the node lingers.
void CameraNode::State::PublishingLoop() {
  while (!halt) {
    std::optional<PublishJob> job = publish_queue.Pop(std::chrono::milliseconds(100));
    if (!job) {
      if (publish_queue.closed()) break;
      if (processing_done && publish_queue.size() == 0) publishing_done = true;
      continue;
    }
    if (!transport->PublishHull(job->hull, halt)) break;
    if (job->contour && !transport->PublishContour(*job->contour, halt)) break;
    ++(job->resent ? resent : published);
  }
  publishing_done = true;
}

silnet_wire_NodeStatus CameraNode::State::Status(double fps, double cpu_percent,
                                                 const std::string& state) {
  silnet_wire_NodeStatus status{};
  dds::CopyBoundedString(options.processing.camera_id, status.camera_id, "camera id");
  status.session = options.processing.session;
  status.time_ns = RealtimeNowNs();
  status.fps = fps;
  status.cpu_percent = cpu_percent;
  status.frames_captured = captured.load();
  status.frames_published = published.load();
  status.frames_dropped = dropped.load();
  status.frames_flagged = flagged.load();
  status.queue_depth = static_cast<uint32_t>(processing_queue.size() + publish_queue.size());
  status.queue_capacity =
      static_cast<uint32_t>(processing_queue.capacity() + publish_queue.capacity());
  {
    std::lock_guard lock(recorder_mutex);
    status.recording = recorder != nullptr;
  }
  dds::CopyBoundedString(state.substr(0, 127), status.state, "state");
  return status;
}

void CameraNode::State::PublishInfo() {
  CameraInfoRecord copy;
  {
    std::lock_guard lock(info_mutex);
    copy = info;
  }
  transport->PublishCameraInfo(copy);
  Record(SessionRecordType::kCameraInfo, SerializeCameraInfo(copy));
}

void CameraNode::State::HandleCommand(const silnet_wire_Command& command) {
  ++commands;
  const std::string name = dds::ReadBoundedString(command.parameter.name);
  const std::string value = dds::ReadBoundedString(command.parameter.value);
  switch (command.kind) {
    case silnet_wire_COMMAND_START:
      spdlog::info("command {}: start", command.command_id);
      stopped = false;
      break;
    case silnet_wire_COMMAND_STOP:
      spdlog::info("command {}: stop", command.command_id);
      stopped = true;
      break;
    case silnet_wire_COMMAND_RECORD_START: {
      const std::filesystem::path dir =
          value.empty() ? options.record_dir : std::filesystem::path(value);
      if (dir.empty()) {
        spdlog::warn("command {}: record start without a folder", command.command_id);
        break;
      }
      auto next = std::make_unique<FrameRecorder>(dir, options.processing.camera_id);
      try {
        next->Open();
      } catch (const InputError& e) {
        SetError(e.what());
        spdlog::error("command {}: {}", command.command_id, e.what());
        break;
      }
      spdlog::info("command {}: recording to {}", command.command_id, next->path().string());
      {
        std::lock_guard lock(recorder_mutex);
        if (recorder) recorder->Flush();
        recorder = std::move(next);
      }
      PublishInfo();
      break;
    }
    case silnet_wire_COMMAND_RECORD_STOP: {
      std::lock_guard lock(recorder_mutex);
      if (recorder) recorder->Flush();
      recorder.reset();
      spdlog::info("command {}: recording stopped", command.command_id);
      break;
    }
    case silnet_wire_COMMAND_SET_PARAMETER: {
      std::string error;
      bool ok = false;
      {
        std::lock_guard lock(processor_mutex);
        ok = processor->SetParameter(name, value, &error);
      }
      if (!ok) {
        spdlog::warn("command {}: {}", command.command_id, error);
        SetError(error);
        break;
      }
      spdlog::info("command {}: {} = {}", command.command_id, name, value);
      {
        std::lock_guard lock(info_mutex);
        info.parameters[name] = value;
        if (name == "method") info.segmentation = value;
      }
      PublishInfo();
      break;
    }
    case silnet_wire_COMMAND_CAPTURE_STILL: {
      // The aggregator repeats a request it got no answer to: send the held still again.
      if (still_store.Find(command.still_id)) {
        spdlog::info("command {}: still {} asked for again; re-sending it", command.command_id,
                     command.still_id);
        StillJob again;
        again.still_id = command.still_id;
        still_queue.TryPush(std::move(again));
        break;
      }
      const bool background = name == dds::kStillKind && value == dds::kBackgroundStill;
      if (background) {
        std::lock_guard lock(background_mutex);
        background_ids.insert(command.still_id);
      }
      still_requests.Add(command.still_id, command.from_frame);
      spdlog::info("command {}: still {}{} from frame {} on", command.command_id, command.still_id,
                   background ? " of the empty scene" : "", command.from_frame);
      break;
    }
    case silnet_wire_COMMAND_RESEND_STILL: {
      StillJob job;
      job.still_id = command.still_id;
      job.part = command.still_part;
      job.first_chunk = static_cast<uint32_t>(std::min<uint64_t>(command.from_frame, UINT32_MAX));
      job.last_chunk = static_cast<uint32_t>(std::min<uint64_t>(command.to_frame, UINT32_MAX));
      if (!still_queue.TryPush(std::move(job)))
        spdlog::warn("command {}: still queue full; resend ignored", command.command_id);
      break;
    }
    case silnet_wire_COMMAND_RESEND: {
      if (command.session != 0 && command.session != options.processing.session) {
        ResendFromRecording(command);
        break;
      }
      size_t queued = 0;
      for (HistoryEntry& entry : history.Range(command.from_frame, command.to_frame)) {
        entry.hull.flags |= silnet_wire_FRAME_RESENT;
        if (entry.contour) entry.contour->flags |= silnet_wire_FRAME_RESENT;
        if (publish_queue.TryPush(
                PublishJob{std::move(entry.hull), std::move(entry.contour), true}))
          ++queued;
      }
      spdlog::info("command {}: re-sending {} frames of [{}, {}]", command.command_id, queued,
                   command.from_frame, command.to_frame);
      break;
    }
    default:
      spdlog::warn("command {}: unknown kind {}", command.command_id,
                   static_cast<int>(command.kind));
  }
}

// A resend request for an earlier session (this node restarted, after a crash perhaps) is
// served from the node's recording, which outlives the process; without one nothing is held.
void CameraNode::State::ResendFromRecording(const silnet_wire_Command& command) {
  std::filesystem::path log;
  {
    std::lock_guard lock(recorder_mutex);
    if (!recorder) {
      spdlog::info("command {}: resend for session {} (this is {}): not recorded, nothing held",
                   command.command_id, command.session, options.processing.session);
      return;
    }
    log = recorder->path();
  }
  // Read without holding the recorder: earlier sessions are complete in the file, and the
  // reader stops cleanly at a record the current session is appending.
  std::vector<SessionFrames> sessions;
  try {
    sessions = ReadSessionLog(log);
  } catch (const InputError& e) {
    spdlog::warn("command {}: cannot read the recording: {}", command.command_id, e.what());
    return;
  }
  size_t queued = 0;
  for (SessionFrames& s : sessions) {
    if (s.session != command.session) continue;
    auto contour = s.contours.begin();
    for (FrameRecord& hull : s.hulls) {
      if (hull.frame_index < command.from_frame || hull.frame_index > command.to_frame) continue;
      while (contour != s.contours.end() && contour->frame_index < hull.frame_index)
        ++contour;
      PublishJob job{std::move(hull), std::nullopt, true};
      job.hull.flags |= silnet_wire_FRAME_RESENT;
      if (contour != s.contours.end() && contour->frame_index == job.hull.frame_index) {
        job.contour = std::move(*contour);
        job.contour->flags |= silnet_wire_FRAME_RESENT;
      }
      if (publish_queue.TryPush(std::move(job))) ++queued;
    }
  }
  spdlog::info("command {}: re-sending {} recorded frames of session {} from frame {}",
               command.command_id, queued, command.session, command.from_frame);
}

// Hands stills `ids` of frame `frame` to the still thread, with the silhouette's flags (a
// silhouette of a warming-up background model is sent, and reported as such). Frames without
// a silhouette (unusable input) satisfy no request: it waits for the next frame.
void CameraNode::State::QueueStills(const std::vector<uint64_t>& ids, const CapturedFrame& frame,
                                    const cv::Mat& silhouette, uint32_t flags) {
  for (uint64_t id : ids) {
    StillJob job;
    job.still_id = id;
    {
      std::lock_guard lock(background_mutex);
      job.background = background_ids.erase(id) > 0;
    }
    job.frame_index = frame.frame_index;
    job.frame_flags = flags;
    job.capture_time_ns = frame.capture_time_ns;
    job.photo = frame.image;
    job.silhouette = silhouette.clone();
    if (!still_queue.TryPush(std::move(job))) {
      SetError(fmt::format("still {}: queue full, not taken", id));
      spdlog::warn("still {}: still queue full, not taken", id);
    }
  }
}

// The photo and silhouette of a still: the frame and its silhouette, or the source's own
// still segmented against the still stream's background (the source's own, else the node's
// last still of the empty scene at that size; else the frame's silhouette brought to the
// still's size). A still of the empty scene is kept as that background; its silhouette is
// empty.
StillPicture CameraNode::State::PictureOf(const StillJob& job) {
  CapturedFrame frame;
  frame.frame_index = job.frame_index;
  frame.capture_time_ns = job.capture_time_ns;
  frame.image = job.photo;
  std::optional<StillPhoto> own = source->TakeStill(frame);
  cv::Mat photo = own ? own->photo : job.photo;
  if (job.background) {
    std::lock_guard lock(background_mutex);
    still_background = photo.clone();
    spdlog::info("still {}: kept as the empty scene ({}x{})", job.still_id, photo.cols, photo.rows);
    return {photo, cv::Mat::zeros(photo.size(), CV_8UC1), silnet_wire_FRAME_EMPTY};
  }
  if (!own) return {job.photo, job.silhouette, job.frame_flags};
  cv::Mat background = own->background;
  if (background.empty()) {
    std::lock_guard lock(background_mutex);
    if (still_background.size() == photo.size() && still_background.type() == photo.type())
      background = still_background;
  }
  if (background.empty()) {
    cv::Mat resized;
    cv::resize(job.silhouette, resized, photo.size(), 0, 0, cv::INTER_LINEAR);
    return {photo, resized >= 128, job.frame_flags};
  }
  // Weak evidence beside the silhouette is marked for the aggregator's multi-view check.
  BackgroundDifferenceOptions segmentation;
  segmentation.mark_weak_silhouette = true;
  cv::Mat mask = SegmentAgainstBackground(photo, background, segmentation).mask;
  const uint32_t flags = cv::countNonZero(mask == 255) == 0 ? silnet_wire_FRAME_EMPTY : 0u;
  return {photo, std::move(mask), flags};
}

// A finite source has ended (the node lingers): requests that the last frame satisfies (asked
// for it or earlier, or for "the next frame") are answered with it; later ones cannot be.
void CameraNode::State::AnswerStillsAfterTheEnd() {
  std::lock_guard lock(latest_mutex);
  if (!latest_mask.empty()) {
    QueueStills(still_requests.TakeDue(latest_frame.frame_index), latest_frame, latest_mask,
                latest_flags);
  }
  for (uint64_t id : still_requests.TakeDue(UINT64_MAX)) {
    SetError(fmt::format("still {}: the source ended before its frame", id));
    spdlog::warn("still {}: the source ended before its frame; not taken", id);
  }
}

void CameraNode::State::SendStill(const StillJob& job) {
  EncodedStill still;
  try {
    const StillPicture picture = PictureOf(job);
    still = EncodeStill(job.still_id, job.frame_index, picture.flags, job.capture_time_ns,
                        picture.photo, picture.silhouette);
  } catch (const InputError& e) {
    SetError(fmt::format("still {}: {}", job.still_id, e.what()));
    spdlog::error("still {}: {}", job.still_id, e.what());
    return;
  }
  still_store.Add(still);
  size_t chunks = 0;
  for (silnet_wire_StillPart part : {silnet_wire_STILL_PHOTO, silnet_wire_STILL_SILHOUETTE}) {
    chunks += transport->PublishStillChunks(still, part, 0, UINT32_MAX, options.still_chunk_bytes,
                                            options.still_faults, halt);
  }
  ++stills;
  spdlog::info("still {}: frame {}, {}x{}, {} + {} bytes in {} chunks sent", job.still_id,
               job.frame_index, still.width, still.height, still.photo.size(),
               still.silhouette.size(), chunks);
}

void CameraNode::State::ResendStill(const StillJob& job) {
  const std::optional<EncodedStill> still = still_store.Find(job.still_id);
  if (!still) {
    spdlog::warn("still {}: asked to re-send it, but it is not held", job.still_id);
    return;
  }
  size_t chunks = 0;
  for (silnet_wire_StillPart part : {silnet_wire_STILL_PHOTO, silnet_wire_STILL_SILHOUETTE}) {
    if (job.part && *job.part != part) continue;
    chunks += transport->PublishStillChunks(*still, part, job.first_chunk, job.last_chunk,
                                            options.still_chunk_bytes, StillChunkFaults{}, halt);
  }
  still_chunks_resent += chunks;
  spdlog::info("still {}: {} chunks re-sent", job.still_id, chunks);
}

// Encodes and sends stills, and re-sends their chunks, off the processing thread.
void CameraNode::State::StillLoop() {
  while (!halt) {
    std::optional<StillJob> job = still_queue.Pop(std::chrono::milliseconds(100));
    if (!job) {
      if (still_queue.closed()) break;
      continue;
    }
    if (job->photo.empty())
      ResendStill(*job);
    else
      SendStill(*job);
  }
}

void CameraNode::State::ControlLoop() {
  auto next_status = Clock::now();
  auto last_time = Clock::now();
  double last_cpu = CpuSeconds();
  uint64_t last_processed = 0;
  while (!halt) {
    for (const silnet_wire_Command& command :
         transport->TakeCommands(std::chrono::milliseconds(100))) {
      HandleCommand(command);
    }
    if (source_ended && processing_done && still_requests.waiting() > 0) {
      AnswerStillsAfterTheEnd();
    }
    const auto now = Clock::now();
    if (now < next_status) continue;
    next_status = now + options.status_period;
    const double seconds = std::chrono::duration<double>(now - last_time).count();
    const double cpu = CpuSeconds();
    const double fps =
        seconds > 0 ? static_cast<double>(processed.load() - last_processed) / seconds : 0.0;
    const double cpu_percent = seconds > 0 ? 100.0 * (cpu - last_cpu) / seconds : 0.0;
    last_time = now;
    last_cpu = cpu;
    last_processed = processed.load();
    std::string state = stopped ? "stopped" : (source_ended ? "ended" : "running");
    {
      std::lock_guard lock(recorder_mutex);
      if (recorder && !recorder->counters().last_error.empty()) {
        state += "; recording paused: " + recorder->counters().last_error;
      }
    }
    {
      std::lock_guard lock(error_mutex);
      if (!last_error.empty()) state += "; last error: " + last_error;
    }
    transport->PublishStatus(Status(fps, cpu_percent, state));
  }
}

CameraNode::CameraNode(CameraNodeOptions options, std::unique_ptr<CaptureSource> source)
    : state_(std::make_unique<State>(std::move(options), std::move(source))) {}

CameraNode::~CameraNode() = default;

void CameraNode::Run(const std::atomic<bool>& stop) {
  State& s = *state_;
  if (const std::string reason = s.options.Validate(); !reason.empty()) throw InputError(reason);
  s.source->Open();
  s.format = s.source->Format();
  spdlog::info("{}: capturing {}", s.options.processing.camera_id, s.source->Describe());
  s.processor =
      std::make_unique<FrameProcessor>(s.options.processing, s.format.width, s.format.height);
  s.transport = std::make_unique<NodeTransport>(s.options.domain, s.options.processing.camera_id,
                                                s.options.qos);
  s.info.camera_id = s.options.processing.camera_id;
  s.info.session = s.options.processing.session;
  s.info.host = HostName();
  s.info.node_version = NodeVersion();
  s.info.source_kind = s.source->Kind();
  s.info.width = static_cast<uint16_t>(s.format.width);
  s.info.height = static_cast<uint16_t>(s.format.height);
  s.info.nominal_fps = s.format.fps;
  s.info.segmentation = ToString(s.options.processing.segmentation.method);
  s.info.parameters = s.options.processing.segmentation.ToMap();
  s.info.parameters["contour_every"] = std::to_string(s.options.processing.contour_every);
  if (!s.options.record_dir.empty()) {
    s.recorder =
        std::make_unique<FrameRecorder>(s.options.record_dir, s.options.processing.camera_id);
    s.recorder->Open();
    spdlog::info("recording to {}", s.recorder->path().string());
  }
  s.PublishInfo();

  std::thread capture([&s] { s.CaptureLoop(); });
  std::thread processing([&s] { s.ProcessingLoop(); });
  std::thread publishing([&s] { s.PublishingLoop(); });
  std::thread control([&s] { s.ControlLoop(); });
  std::thread stills([&s] { s.StillLoop(); });

  // Run until asked to stop, or until a finite source is done, published and lingered.
  std::optional<Clock::time_point> done_at;
  while (!stop) {
    if (s.publishing_done && !done_at) {
      done_at = Clock::now();
      spdlog::info("all frames published; staying {} ms for resend requests",
                   s.options.linger.count());
    }
    if (done_at && Clock::now() - *done_at >= s.options.linger) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // Graceful stop: no more capture, let processing and publishing drain for a while.
  s.stop_capture = true;
  capture.join();
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (!s.publishing_done && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (!s.publishing_done)
    spdlog::warn("stopping with {} frames unpublished", s.publish_queue.size());
  else
    s.transport->WaitForAcknowledgements(std::chrono::seconds(2));
  s.halt = true;
  s.processing_queue.Close();
  s.publish_queue.Close();
  s.still_queue.Close();
  processing.join();
  stills.join();
  publishing.join();
  control.join();
  s.source->Close();
  {
    std::lock_guard lock(s.recorder_mutex);
    if (s.recorder) s.recorder->Flush();
  }
  s.transport->PublishStatus(s.Status(0.0, 0.0, "exited"));
  const NodeCounters c = Counters();
  spdlog::info("{}: {} captured, {} published, {} dropped, {} flagged, {} re-sent",
               s.options.processing.camera_id, c.captured, c.published, c.dropped, c.flagged,
               c.resent);
}

NodeCounters CameraNode::Counters() const {
  const State& s = *state_;
  NodeCounters c;
  c.captured = s.captured.load();
  c.processed = s.processed.load();
  c.published = s.published.load();
  c.dropped = s.dropped.load();
  c.flagged = s.flagged.load();
  c.resent = s.resent.load();
  c.commands = s.commands.load();
  c.capture_errors = s.capture_errors.load();
  c.stills = s.stills.load();
  c.still_chunks_resent = s.still_chunks_resent.load();
  return c;
}

}  // namespace silnet::node

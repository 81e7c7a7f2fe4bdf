#pragma once
// Live capture from a Video4Linux2 device (USB webcams and most Linux camera drivers) with
// memory-mapped streaming I/O, decoding YUYV or Motion-JPEG frames to BGR, riding out a
// camera that is unplugged and plugged back in, and taking full-resolution stills by
// switching the camera to its largest frame size for one photograph and back.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "node/capture/capture_source.h"
#include "node/capture/v4l2/v4l2_device.h"

struct v4l2_buffer;

namespace silnet::node {

// The pixel format V4l2Source asks the device for.
enum class V4l2PixelFormat {
  kAuto,   // YUYV if the device grants it at the asked rate, else whichever of YUYV and
           // Motion-JPEG the device grants the higher rate
  kYuyv,   // packed YUV 4:2:2 (no decoding cost, but much USB bandwidth)
  kMjpeg,  // Motion-JPEG (decoded on the host; bytes per frame vary)
};

// What V4l2Source opens and asks for. The device may grant another size or rate; the
// source uses what it grants (see V4l2Source::Format()).
struct V4l2SourceOptions {
  // The device node.
  std::string device = "/dev/video0";
  // Asked frame size in pixels (> 0).
  int width = 640;
  int height = 480;
  // Asked frames per second (> 0).
  double fps = 30.0;
  // Asked pixel format.
  V4l2PixelFormat pixel_format = V4l2PixelFormat::kAuto;
  // Memory-mapped buffers to ask for (1..32; the driver may grant another number).
  int buffer_count = 4;
  // After the device disappears, re-open attempts are at least this far apart (>= 0).
  std::chrono::milliseconds reopen_interval{1000};
  // TakeStill() photographs at the largest frame size of the video's aspect ratio the
  // device offers (false: stills are the video frames themselves).
  bool full_resolution_stills = true;
  // Frames discarded after switching to the still size while exposure settles (>= 0).
  int still_settle_frames = 3;
  // Longest a TakeStill() waits for its photograph, from its call (> 0).
  std::chrono::milliseconds still_timeout{10000};
};

// Frames of a V4L2 video capture device as CV_8UC3 BGR.
//
// frame_index is 0 for the first frame after Open() and then follows the driver's sequence
// numbers: when n sequence numbers are missing, the index skips n as well and n frames are
// counted as dropped, so indices stay proportional to time. capture_time_ns is the driver's
// timestamp moved to CLOCK_REALTIME when the driver stamps buffers with CLOCK_MONOTONIC, else
// CLOCK_REALTIME when the buffer is dequeued.
//
// A buffer the driver flags as erroneous, a corrupt or truncated JPEG and a short or
// wrong-size frame give a per-frame kFrameError: frame_index and capture_time_ns name the frame,
// the image is empty, and the frame is counted in errors and dropped. Every dequeued buffer
// is queued again before Read() returns.
//
// When the device disappears (ENODEV or EIO, or poll reporting an error) the source releases
// it and returns kError once (frame->capture_time_ns is 0: no frame concerned); later Read()
// calls try to re-open it at most once per reopen_interval and return kTimeout while it is
// away. Once it is back, streaming resumes, Counters().reopens grows by one, and frame_index
// continues from the last index plus the frame periods that elapsed between the last frame
// before and the first frame after (those frames are counted as dropped).
//
// Full-resolution stills: Open() enumerates the frame sizes the device offers in YUYV and
// Motion-JPEG (VIDIOC_ENUM_FRAMESIZES; discrete, stepwise and continuous) and picks the
// largest one, larger in area than the video, whose aspect ratio is the video's within 1 %
// (the calibration at the video size is carried to the still by scaling; another aspect
// ratio would be another crop); on equal sizes Motion-JPEG, which USB cameras deliver faster.
// TakeStill() posts a request and waits; the next Read() performs it before reading: it stops
// streaming and frees the buffers, sets the still size, streams with two buffers, discards
// still_settle_frames frames, decodes the next good one (skipping at most three bad ones),
// then restores the video format exactly as negotiated (size, pixel format, frame interval)
// and streams again. The frames the switch cost count as dropped and frame_index continues by
// elapsed time as after a re-open. When the video format cannot be restored (the device is
// gone, the driver refuses), that Read() reports kError and the source re-opens the device as
// when it disappears. The still is taken after the frame that satisfied the request, some
// frame periods later; the node brings that frame's silhouette to the still's size.
//
// Threads: Open(), Read() and Close() are called from one thread; TakeStill(), StillRequested()
// and Describe() may be called from any thread meanwhile. The source must outlive those calls.
class V4l2Source : public CaptureSource {
 public:
  // Checks the options (throws CaptureError naming the device if one is out of range); the
  // device is not opened before Open(). `device` defaults to the system calls.
  explicit V4l2Source(V4l2SourceOptions options,
                      std::unique_ptr<V4l2Device> device = MakeSystemV4l2Device());
  // Closes the device.
  ~V4l2Source() override;

  V4l2Source(const V4l2Source&) = delete;
  V4l2Source& operator=(const V4l2Source&) = delete;

  // Opens the device, negotiates size, pixel format and rate (using what the driver grants
  // and warning when it differs from the options), looks up the still size (when
  // full_resolution_stills), maps the buffers and starts streaming.
  // Throws CaptureError naming the device when it cannot be opened, is not a V4L2 video
  // capture device with streaming I/O, offers neither YUYV nor Motion-JPEG, or refuses the
  // buffers; nothing stays open then. Open() on an open source starts over: frame_index
  // restarts at 0 and counters keep running.
  void Open() override;
  // Waits up to `timeout` for the next frame; see the class comment for the outcomes. When a
  // still is requested it is taken first, which may make this call last up to still_timeout
  // longer.
  CaptureStatus Read(CapturedFrame* frame, std::chrono::milliseconds timeout) override;
  // Stops streaming, unmaps the buffers and closes the device; safe to call twice. Read()
  // needs a new Open() afterwards. A TakeStill() waiting meanwhile throws CaptureError.
  void Close() override;
  // A photograph at the still size (background empty), taken by the next Read(); nullopt
  // when full_resolution_stills is off or the device offers no larger size of the video's
  // aspect ratio (the frame is the still then). `frame` is not used. Thread-safe; one request
  // at a time (concurrent calls queue). Throws CaptureError naming the device when the source
  // is not open, the device is away, the switch fails, no Read() performs the request within
  // still_timeout, or Close() is called while it waits.
  std::optional<StillPhoto> TakeStill(const CapturedFrame& frame) override;
  // True while a TakeStill() waits for a Read() to take its request. Thread-safe.
  bool StillRequested() const;

  // Size, rate (0 if the driver does not tell) and pixel format ("YUYV", "MJPG" or "JPEG")
  // the driver granted; valid after Open().
  CaptureFormat Format() const override { return format_; }
  // "v4l2".
  std::string Kind() const override { return "v4l2"; }
  // For example "v4l2:/dev/video0 640x480 YUYV 30 fps" ("v4l2:/dev/video0 (not open)" before
  // the first Open()). Thread-safe.
  std::string Describe() const override;
  // Reason of the last kError, naming the device.
  std::string LastError() const override { return last_error_; }
  // Frames delivered, frames lost (sequence gaps, bad frames, time away), kError results and
  // successful re-opens.
  CaptureCounters Counters() const override { return counters_; }

 private:
  using Clock = std::chrono::steady_clock;

  enum class State {
    kClosed,     // never opened, or closed by Close()
    kStreaming,  // open and streaming
    kAway,       // the device disappeared; waiting to re-open it
  };

  // One memory-mapped buffer.
  struct Buffer {
    void* address = nullptr;
    size_t length = 0;
  };

  // The format the driver granted for one S_FMT/S_PARM attempt.
  struct Negotiated {
    uint32_t pixel_format = 0;
    int width = 0;
    int height = 0;
    int bytes_per_line = 0;
    double fps = 0.0;  // 0 if the driver does not support setting the rate
    // The frame interval (seconds per frame) the driver granted, or the one asked for when it
    // does not tell: what restoring this format asks for again.
    uint32_t interval_numerator = 0;
    uint32_t interval_denominator = 0;
  };

  // The format stills are taken in.
  struct StillTarget {
    uint32_t pixel_format = 0;
    int width = 0;
    int height = 0;
  };

  // A TakeStill() call waiting for the capture thread.
  struct StillRequest {
    uint64_t id = 0;
    Clock::time_point deadline;  // the caller gives up then
  };

  // What the capture thread hands to the waiting TakeStill().
  struct StillAnswer {
    uint64_t id = 0;  // the request answered (0: none)
    cv::Mat photo;
    std::string error;  // non-empty: the still failed
  };

  // Opens, negotiates, looks up the still size, maps and starts streaming; throws
  // CaptureError with everything released on failure.
  void OpenDevice();
  // The steps of OpenDevice().
  void CheckCapabilities();
  void NegotiateFormat();
  Negotiated Negotiate(uint32_t pixel_format);
  // S_FMT of `pixel_format` at width x height, then G_FMT: the granted format (no rate).
  Negotiated SetFormat(uint32_t pixel_format, int width, int height);
  // S_PARM of the frame interval numerator/denominator (G_PARM when the driver cannot set
  // it); fills the rate fields of `result`.
  void SetRate(uint32_t numerator, uint32_t denominator, Negotiated* result);
  // The largest frame size of the video's aspect ratio larger than the video in YUYV or
  // Motion-JPEG; nullopt if none.
  std::optional<StillTarget> FindStillTarget();
  // Requests `buffer_count` buffers, maps and queues them and starts streaming.
  void StartStreaming(int buffer_count);
  // Stops streaming (if the device is still there), unmaps and frees the buffers.
  void StopStreaming();
  // StopStreaming() and closes the device.
  void ReleaseDevice();

  // Read() while the device is away: waits for the next re-open attempt within `deadline`.
  // True if the device is streaming again.
  bool WaitAndReopen(Clock::time_point deadline);
  // Read() while streaming.
  CaptureStatus ReadStreaming(CapturedFrame* frame, Clock::time_point deadline);
  // Releases the vanished device and reports it (kError).
  CaptureStatus DeviceLost(CapturedFrame* frame, const std::string& reason);
  // frame_index of a dequeued buffer; counts the frames a gap skipped.
  uint64_t IndexOf(uint32_t sequence, int64_t capture_time_ns);
  // Decodes the buffer's bytes in `format` into `image`; the reason of failure otherwise.
  std::string Decode(const v4l2_buffer& buffer, const Negotiated& format, cv::Mat* image) const;
  // The rate used to turn elapsed time into frame periods.
  double PeriodFps() const;

  // Takes the pending still request, if any (capture thread).
  std::optional<StillRequest> TakeStillRequest();
  // Hands the result of request `id` to its TakeStill() if it still waits.
  void AnswerStill(uint64_t id, cv::Mat photo, std::string error);
  // Performs `request` while streaming: switches to the still format, takes the photo,
  // answers, and restores the video stream. Returns "" or why the video stream could not be
  // restored (the device is then released by the caller).
  std::string ServeStill(const StillRequest& request, const StillTarget& target);
  // The photograph at `target`, streaming must be stopped; throws CaptureError.
  cv::Mat CaptureStill(const StillTarget& target, Clock::time_point deadline);
  // Sets the video format negotiated at Open() again and streams; throws CaptureError.
  void RestoreVideo();
  // Updates what Describe() returns from format_.
  void UpdateDescription();

  // "v4l2:<device>: " + message.
  std::string DeviceMessage(const std::string& message) const;
  // A CaptureError for a failed call, with errno's text.
  [[noreturn]] void ThrowCallError(const std::string& what, int error) const;

  // Capture thread only (Open/Read/Close).
  V4l2SourceOptions options_;
  std::unique_ptr<V4l2Device> device_;
  State state_ = State::kClosed;
  int fd_ = -1;
  bool streaming_ = false;
  bool buffers_requested_ = false;
  std::vector<Buffer> buffers_;
  Negotiated negotiated_;
  CaptureFormat format_;
  bool opened_once_ = false;

  // frame_index bookkeeping.
  bool have_last_ = false;  // a buffer has been indexed since Open()
  bool resync_ = false;     // the next buffer is the first after a re-open or a still
  uint64_t last_index_ = 0;
  uint32_t last_sequence_ = 0;
  int64_t last_time_ns_ = 0;

  Clock::time_point last_reopen_attempt_;
  CaptureCounters counters_;
  std::string last_error_;

  // Shared with TakeStill(), StillRequested() and Describe() callers, guarded by mutex_.
  mutable std::mutex mutex_;
  std::condition_variable still_answered_;
  std::string description_;
  bool accepting_stills_ = false;            // open (streaming or away)
  std::optional<StillTarget> still_target_;  // from the last Open() or re-open
  uint64_t last_still_id_ = 0;
  std::optional<StillRequest> pending_still_;  // posted, not taken by the capture thread yet
  uint64_t waiting_still_id_ = 0;              // the request a TakeStill() waits for (0: none)
  StillAnswer still_answer_;
  // Makes TakeStill() calls one at a time.
  std::mutex still_call_mutex_;
};

}  // namespace silnet::node

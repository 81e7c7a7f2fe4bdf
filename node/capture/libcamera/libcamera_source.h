#pragma once
// Cameras driven through libcamera (Raspberry Pi camera modules, UVC webcams behind libcamera's
// uvcvideo pipeline, ...), with full-resolution stills from a still-capture stream when the
// camera offers one. Written against libcamera 0.0.3 (Debian 12); libcamera stays out of this
// header so only libcamera_source.cc needs its headers.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "node/capture/capture_source.h"

namespace silnet::node {

// Which camera LibcameraSource opens and what it asks of it.
struct LibcameraSourceOptions {
  // libcamera camera id (as `cam --list` prints it); empty = the camera at `camera_index`.
  std::string camera_id;
  // Position in libcamera's camera list, used when `camera_id` is empty.
  int camera_index = 0;
  // Requested size; both 0 keep the camera's default for video recording. The camera may
  // grant another size (see Format()).
  int width = 640;
  int height = 480;
  // Requested frame rate, applied through FrameDurationLimits when the camera supports it;
  // 0 = the camera's default.
  double fps = 30.0;
  // libcamera pixel format name ("YUYV", "MJPEG", "NV12", "RGB888", ...); empty = the first
  // of YUYV, MJPEG, NV12, RGB888, BGR888, UYVY, YVYU, NV21, YUV420, XRGB8888, XBGR8888 the
  // camera offers.
  std::string pixel_format;
  // Frame buffers (and requests) in flight; 0 = libcamera's default.
  int buffer_count = 4;
  // Configure a still-capture stream beside the video (at the largest size of the video's
  // aspect ratio) for TakeStill(); false, or a camera that cannot, makes stills the video
  // frames themselves.
  bool still_capture = true;
  // Longest a TakeStill() waits for its photograph, from its call (> 0).
  std::chrono::milliseconds still_timeout{10000};
};

// A libcamera camera as a capture source delivering CV_8UC3 BGR frames. frame_index comes from
// the buffers' sequence numbers (counted from the first delivered frame, so a gap is a lost
// frame and is added to Counters().dropped); capture_time_ns is the sensor timestamp
// (CLOCK_MONOTONIC) converted to CLOCK_REALTIME. A failed or undecodable frame is a per-frame
// kFrameError (counted in errors and dropped); a camera that disappears gives kError without a
// frame. One process-wide libcamera CameraManager is shared by all sources and stopped with the
// last of them.
//
// Stills: when still_capture is set, Open() asks for a configuration of two streams, the video
// (configured exactly as without stills: size, pixel format, buffer count, colour space, frame
// duration) and a still-capture stream at the largest size the camera offers in a pixel format
// this source converts, larger than the video and of its aspect ratio within 1 % (another
// aspect ratio would be another crop of the calibrated view). When the camera cannot (one
// stream only, the configuration is invalid, changes the video or moves the still off that
// size, configuring or allocating the still buffers fails) the video is configured alone and
// one info line says why stills are the video frames. TakeStill() posts a request; Read() adds
// the still buffer to the next request it gives back to the camera, and when that request
// completes copies the still out (the request's video frame is delivered as usual); TakeStill()
// converts the copy to BGR on its own thread. The still is taken some frames after the frame
// that satisfied the request; the node brings that frame's silhouette to the still's size.
//
// Threads: Open(), Read() and Close() are called from one thread; TakeStill() may be called
// from any thread meanwhile. The source must outlive those calls.
class LibcameraSource : public CaptureSource {
 public:
  // Stores the options; libcamera is not touched before Open().
  explicit LibcameraSource(LibcameraSourceOptions options);
  // Stops and releases the camera (as Close()).
  ~LibcameraSource() override;
  LibcameraSource(const LibcameraSource&) = delete;
  LibcameraSource& operator=(const LibcameraSource&) = delete;

  // Starts libcamera, acquires and configures the camera, allocates and maps its buffers and
  // starts streaming. Throws CaptureError (with nothing left acquired) if libcamera cannot
  // start, the camera does not exist (the message lists the cameras that do), is in use, or
  // offers no pixel format this source converts.
  void Open() override;
  // Waits up to `timeout` for the next completed frame and returns it converted to BGR (the
  // buffer goes back to the camera at once). kTimeout if none completed in time.
  CaptureStatus Read(CapturedFrame* frame, std::chrono::milliseconds timeout) override;
  // Stops streaming, frees the buffers and releases the camera; safe to call twice. A
  // TakeStill() waiting meanwhile throws CaptureError.
  void Close() override;
  // A photograph from the still-capture stream (background empty), taken with a request Read()
  // gives back to the camera; nullopt when still_capture is off or the camera has no still
  // stream (the frame is the still then). `frame` is not used. Thread-safe; one request at a
  // time (concurrent calls queue). Throws CaptureError naming the camera when the source is not
  // open, the camera disconnected, the still buffer failed or was cancelled, no still arrived
  // within still_timeout, Close() was called while it waited, or the still cannot be converted.
  std::optional<StillPhoto> TakeStill(const CapturedFrame& frame) override;

  // The granted size and pixel format; fps is the requested rate if the camera accepted a
  // frame duration limit, else 0 (unknown).
  CaptureFormat Format() const override { return format_; }
  // "libcamera".
  std::string Kind() const override { return "libcamera"; }
  // For example "libcamera:/base/soc/i2c0mux/i2c@1/imx219@10 1640x1232 YUV420 30 fps".
  std::string Describe() const override;
  // Reason of the last kError.
  std::string LastError() const override { return last_error_; }
  // Frames delivered, sequence gaps and failed frames (dropped), kError results.
  CaptureCounters Counters() const override { return counters_; }

 private:
  struct State;       // libcamera objects, buffer mappings and the completed-request queue
  struct StillImage;  // a still's planes copied out of its buffer, with their layout

  // What the capture side hands to the waiting TakeStill().
  struct StillAnswer {
    uint64_t id = 0;  // the request answered (0: none)
    std::shared_ptr<const StillImage> image;
    std::string error;  // non-empty: the still failed
  };

  // The camera as the options name it ("#0" or its id).
  std::string RequestedCamera() const;
  // "libcamera camera <id>: " + message; still_mutex_ must be held.
  std::string StillMessage(const std::string& message) const;
  // Takes the posted still request (0: none); capture side.
  uint64_t TakeStillRequest();
  // True while a TakeStill() waits for request `id`.
  bool StillAwaited(uint64_t id);
  // Hands the result of request `id` to its TakeStill() if it still waits.
  void AnswerStill(uint64_t id, std::shared_ptr<const StillImage> image, std::string error);
  // Fails the waiting and all later TakeStill() calls until the next Open() (libcamera's
  // thread when the camera disconnects).
  void FailStills(const std::string& reason);

  LibcameraSourceOptions options_;  // not changed after construction (any thread reads it)
  // Capture thread only (Open/Read/Close).
  std::unique_ptr<State> state_;
  std::string camera_id_;
  CaptureFormat format_;
  CaptureCounters counters_;
  std::string last_error_;

  // Shared with TakeStill() callers (and libcamera's thread), guarded by still_mutex_.
  std::mutex still_mutex_;
  std::condition_variable still_answered_;
  std::string still_camera_;       // the camera's id once open, else RequestedCamera()
  bool accepting_stills_ = false;  // open
  bool still_stream_ = false;      // open with a still-capture stream
  std::string still_failure_;      // why no still can be taken until the next Open() ("": none)
  uint64_t last_still_id_ = 0;
  uint64_t pending_still_id_ = 0;  // posted, not attached to a request yet (0: none)
  uint64_t waiting_still_id_ = 0;  // the request a TakeStill() waits for (0: none)
  StillAnswer still_answer_;
  // Makes TakeStill() calls one at a time.
  std::mutex still_call_mutex_;
};

}  // namespace silnet::node

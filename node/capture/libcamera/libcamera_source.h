#pragma once
// Cameras driven through libcamera (Raspberry Pi camera modules, UVC webcams behind libcamera's
// uvcvideo pipeline, ...). Written against libcamera 0.0.3 (Debian 12); libcamera stays out of
// this header so only libcamera_source.cc needs its headers.

#include <memory>
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
};

// A libcamera camera as a capture source delivering CV_8UC3 BGR frames. frame_index comes from
// the buffers' sequence numbers (counted from the first delivered frame, so a gap is a lost
// frame and is added to Counters().dropped); capture_time_ns is the sensor timestamp
// (CLOCK_MONOTONIC) converted to CLOCK_REALTIME. A failed or undecodable frame is a per-frame
// kFrameError (counted in errors and dropped); a camera that disappears gives kError without a
// frame. One process-wide libcamera CameraManager is shared by all sources and stopped with the
// last of them.
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
  // Stops streaming, frees the buffers and releases the camera; safe to call twice.
  void Close() override;

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
  struct State;  // libcamera objects, buffer mappings and the completed-request queue

  LibcameraSourceOptions options_;
  std::unique_ptr<State> state_;
  std::string camera_id_;
  CaptureFormat format_;
  CaptureCounters counters_;
  std::string last_error_;
};

}  // namespace silnet::node

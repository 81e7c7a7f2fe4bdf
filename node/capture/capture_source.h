#pragma once
// Every way silnet-node gets images — V4L2 devices, libcamera, video files, image folders,
// replayed simulated cameras — behind one interface, so the node pipeline and its tests do
// not care where frames come from.

#include <chrono>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>

#include "shared/util/check.h"
#include "shared/util/realtime_clock.h"

namespace silnet::node {

// A capture source could not be opened or failed for good; the message is for the user.
class CaptureError : public InputError {
 public:
  using InputError::InputError;
};

// One captured image.
struct CapturedFrame {
  cv::Mat image;                // CV_8UC3 BGR from colour sources, CV_8UC1 from mask sources
  uint64_t frame_index = 0;     // grows by one per frame period; a jump means lost frames
  int64_t capture_time_ns = 0;  // CLOCK_REALTIME at exposure (driver timestamp if known)
};

// What one Read() produced.
enum class CaptureStatus {
  kFrame,        // `frame` holds a new image
  kTimeout,      // nothing within the timeout (a live source may still deliver later)
  kEndOfStream,  // a finite source (file, folder) has no more frames
  kFrameError,   // one frame was unusable (corrupt, wrong size, error-flagged by the driver):
                 // frame->frame_index and capture_time_ns name it, frame->image is empty, so
                 // the node can publish it flagged; see LastError()
  kError,        // the source failed (device gone); it may recover on later reads; see
                 // LastError()
};

// A photograph from a source's own still stream (full resolution), with the empty scene at
// that resolution when the source knows it (for the still's silhouette).
struct StillPhoto {
  cv::Mat photo;       // CV_8UC3 BGR
  cv::Mat background;  // CV_8UC3 of the photo's size, or empty
};

// What the source actually delivers (a device may not grant what was asked).
struct CaptureFormat {
  int width = 0;
  int height = 0;
  double fps = 0.0;          // nominal frames per second (0 if unknown)
  std::string pixel_format;  // e.g. "YUYV", "MJPG", "BGR", "GRAY"
};

// Running totals of a source.
struct CaptureCounters {
  uint64_t frames = 0;   // frames delivered
  uint64_t dropped = 0;  // frames the device or decoder lost (index gaps, bad frames)
  uint64_t errors = 0;   // kError results
  uint64_t reopens = 0;  // successful re-opens after the device disappeared
};

// A source of frames. Not thread-safe: one thread calls Open/Read/Close.
class CaptureSource {
 public:
  virtual ~CaptureSource() = default;

  // Opens the source. Throws CaptureError with a readable reason (missing device or file,
  // unsupported format, ...).
  virtual void Open() = 0;
  // Waits up to `timeout` for the next frame.
  virtual CaptureStatus Read(CapturedFrame* frame, std::chrono::milliseconds timeout) = 0;
  // Releases the device or file; safe to call twice.
  virtual void Close() = 0;

  // Valid after Open().
  virtual CaptureFormat Format() const = 0;
  // Short kind name for CameraInfo: "v4l2", "libcamera", "video", "images", "sim".
  virtual std::string Kind() const = 0;
  // One line for logs, e.g. "v4l2:/dev/video0 640x480 YUYV 30 fps".
  virtual std::string Describe() const = 0;
  // Reason of the last kError.
  virtual std::string LastError() const = 0;
  virtual CaptureCounters Counters() const = 0;
  // The still for a request that `frame` satisfies, from the source's own still stream
  // (libcamera's still-capture stream, a simulated camera's statue); nullopt when the frame
  // itself is the still. Called from the node's still thread while Read() goes on: it must
  // not disturb it. Throws CaptureError when the still stream fails.
  virtual std::optional<StillPhoto> TakeStill(const CapturedFrame& frame) {
    (void)frame;
    return std::nullopt;
  }
};

}  // namespace silnet::node

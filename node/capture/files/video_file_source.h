#pragma once
// A video file replayed as a camera through cv::VideoCapture, optionally released in real
// time so the replay behaves like a live camera.

#include <cstdint>
#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>

#include "node/capture/capture_source.h"
#include "node/capture/files/replayed_frame.h"
#include "node/capture/frame_pacer.h"

namespace silnet::node {

// What VideoFileSource replays and how (ReplayOptions: the timing and size; an fps of 0 takes
// the container's).
struct VideoFileSourceOptions : ReplayOptions {
  // The video file (any container and codec OpenCV's FFmpeg, GStreamer or built-in MJPEG
  // backend decodes).
  std::filesystem::path file;
};

// The frames of a video file as CV_8UC3 BGR. frame_index is the frame's position in decode
// order (counting skipped frames). capture_time_ns is the due time start + (n + offset) / fps
// when the fps is known, whether or not frames are paced, else CLOCK_REALTIME at Read(). A
// frame whose size differs from the expected size is a per-frame kFrameError (counted in errors
// and dropped) and the stream goes on; kEndOfStream follows the last frame the decoder
// returns.
class VideoFileSource : public CaptureSource {
 public:
  // Stores the options; the file is not opened before Open().
  explicit VideoFileSource(VideoFileSourceOptions options);
  ~VideoFileSource() override = default;

  // Opens the file and skips to `first_frame`. Throws CaptureError naming the file if it does
  // not exist, cannot be decoded, or has no frame at `first_frame`, and for inconsistent
  // options (only one of width/height, real_time without a known fps, negative values).
  void Open() override;
  // Returns the next frame (kFrame), a per-frame kFrameError, or kEndOfStream (also on every later
  // call). When paced, waits up to `timeout` for the frame's due time and returns kTimeout if
  // it is not yet due (the decoded frame is kept for the next call); unpaced reads never wait.
  CaptureStatus Read(CapturedFrame* frame, std::chrono::milliseconds timeout) override;
  // Releases the file and any pending frame; safe to call twice. Open() starts over.
  void Close() override;

  // Frame size, nominal fps (0 if unknown) and "BGR".
  CaptureFormat Format() const override { return format_; }
  // "video".
  std::string Kind() const override { return "video"; }
  // For example "video:/data/cam0.avi 640x480 BGR (MJPG via FFMPEG) 30 fps".
  std::string Describe() const override;
  // Reason of the last kError.
  std::string LastError() const override { return last_error_; }
  // Frames delivered, per-frame errors (each also counted as dropped).
  CaptureCounters Counters() const override { return counters_; }

 private:
  // Decodes the next frame into pending_; false at the end of the stream.
  bool DecodeNext();
  // Checks a decoded frame against the expected size and converts it to BGR.
  ReplayedFrame Make(uint64_t delivered, cv::Mat image) const;

  VideoFileSourceOptions options_;
  cv::VideoCapture capture_;
  bool open_ = false;
  bool ended_ = false;
  uint64_t decoded_ = 0;  // frames decoded since first_frame (delivered or pending)
  std::optional<ReplayedFrame> pending_;
  std::optional<FramePacer> pacer_;  // set when the fps is known
  std::string codec_;                // the container's fourcc, e.g. "MJPG"
  std::string backend_;              // the OpenCV backend reading the file, e.g. "FFMPEG"
  CaptureFormat format_;
  CaptureCounters counters_;
  std::string last_error_;
};

}  // namespace silnet::node

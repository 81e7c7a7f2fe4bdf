#pragma once
// A folder of still images replayed as a camera: the frames of a recorded or simulated
// camera (for example <dataset>/<camera>/frames or .../masks), optionally released in real
// time so the replay behaves like a live camera.

#include <cstdint>
#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "node/capture/capture_source.h"
#include "node/capture/files/replayed_frame.h"
#include "node/capture/frame_pacer.h"

namespace silnet::node {

// What ImageFolderSource replays and how (ReplayOptions: the timing and size).
struct ImageFolderSourceOptions : ReplayOptions {
  // Folder holding the images (png, jpg, jpeg, bmp, pbm, pgm, ppm, tif, tiff; any case).
  std::filesystem::path folder;
  // Read images as greyscale CV_8UC1 (silhouette masks) instead of CV_8UC3 BGR.
  bool masks = false;
};

// The images of a folder in file-name order. frame_index is the image's position in the
// sorted listing of the whole folder (so it names the file even with first_frame > 0).
// capture_time_ns is the due time start + (n + offset) / fps when fps > 0, whether or not
// frames are paced, else CLOCK_REALTIME at Read(). A corrupt image, or one whose size differs
// from the expected size, is a per-frame kFrameError (counted in errors and dropped) and the
// stream goes on with the next image; kEndOfStream follows the last image.
class ImageFolderSource : public CaptureSource {
 public:
  // Stores the options; nothing is read before Open().
  explicit ImageFolderSource(ImageFolderSourceOptions options);
  ~ImageFolderSource() override = default;

  // Lists the folder and learns the image size. Throws CaptureError naming the folder if it
  // is missing, holds no images, or `first_frame` is past its last image, and for
  // inconsistent options (only one of width/height, real_time without fps, negative sizes).
  void Open() override;
  // Returns the next image (kFrame), a per-frame kFrameError, or kEndOfStream (also on every later
  // call). When paced, waits up to `timeout` for the frame's due time and returns kTimeout if
  // it is not yet due (the frame is kept for the next call); unpaced reads never wait.
  CaptureStatus Read(CapturedFrame* frame, std::chrono::milliseconds timeout) override;
  // Forgets the listing and any pending frame; safe to call twice. Open() starts over.
  void Close() override;

  // Size of the delivered images, the nominal fps, and "BGR" or "GRAY".
  CaptureFormat Format() const override { return format_; }
  // "images".
  std::string Kind() const override { return "images"; }
  // For example "images:/data/cam0/frames 640x480 BGR 30 fps, 600 images".
  std::string Describe() const override;
  // Reason of the last kError (names the file).
  std::string LastError() const override { return last_error_; }
  // Frames delivered, per-frame errors (each also counted as dropped).
  CaptureCounters Counters() const override { return counters_; }

  // The image files Open() selected, in delivery order (after first_frame and max_frames).
  const std::vector<std::filesystem::path>& Files() const { return files_; }

 private:
  // Decodes files_[position] (empty if it cannot be read).
  cv::Mat Decode(size_t position) const;
  // Checks a decoded image against the expected size and type.
  ReplayedFrame Make(size_t position, cv::Mat image) const;

  ImageFolderSourceOptions options_;
  bool open_ = false;
  std::vector<std::filesystem::path> files_;
  size_t next_ = 0;                       // next position of files_ to load
  std::optional<ReplayedFrame> pending_;  // position: index into files_
  std::optional<FramePacer> pacer_;       // set when fps > 0
  CaptureFormat format_;
  CaptureCounters counters_;
  std::string last_error_;
};

}  // namespace silnet::node

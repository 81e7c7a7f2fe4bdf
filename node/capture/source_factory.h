#pragma once
// Capture sources from a one-line description, as given on silnet-node's command line:
//   v4l2:/dev/video0         a V4L2 device (size, rate, pixel format from the options)
//   libcamera:ID             a libcamera camera by id; libcamera:#N by index (if built)
//   video:/path/file.mp4     a video file
//   images:/path/folder      a folder of colour images
//   masks:/path/folder       a folder of silhouette masks (mask-input segmentation)
//   sim:/dataset/cam03       a simulated camera replayed live: its colour frames paced at
//                            its frame rate and time offset (from ground_truth.yaml); its
//                            stills show /dataset/statue/cam03 when that exists
//   sim-masks:/dataset/cam03 the same camera's exact silhouettes

#include <memory>
#include <string>

#include "node/capture/capture_source.h"

namespace silnet::node {

// Settings that apply to the source kinds that use them.
struct SourceOptions {
  int width = 640;  // v4l2, libcamera: size asked for; files: expected (0 = any)
  int height = 480;
  double fps = 30.0;                  // v4l2, libcamera: rate asked for; files: 0 = the file's
  std::string pixel_format = "auto";  // v4l2: yuyv, mjpeg or auto
  bool video_stills = false;          // v4l2, libcamera: stills at the video size, not larger
  bool real_time = false;             // files: release frames at their due time
  int64_t start_ns = 0;               // pacing: CLOCK_REALTIME of reference time 0 (0 = now)
  double speed = 1.0;                 // sim: replay speed (2 = twice real time)
};

// What a description asks for.
struct SourceDescription {
  std::string kind;      // v4l2, libcamera, video, images, masks, sim, sim-masks
  std::string location;  // device, id, file or folder
  bool masks() const { return kind == "masks" || kind == "sim-masks"; }
};

// Splits "kind:location"; throws InputError naming the accepted kinds for anything else.
SourceDescription ParseSourceDescription(const std::string& text);

// Builds the source (nothing is opened yet). Throws InputError for a kind not available in
// this build (libcamera) or a simulated camera without ground truth.
std::unique_ptr<CaptureSource> MakeCaptureSource(const SourceDescription& description,
                                                 const SourceOptions& options);

}  // namespace silnet::node

#pragma once
// The node's per-frame work: segment a captured frame, reduce the silhouette to its convex
// hull and tangent table (thesis 2.3.1), optionally extract its full contour, set the frame
// flags, and encode the HullFrame and Contour payloads. Transport-free, so tests and
// benchmarks run it without DDS.

#include <cstdint>
#include <optional>
#include <string>

#include "node/capture/capture_source.h"
#include "node/segmentation/silhouette_segmenter.h"
#include "shared/io/frame_record.h"
#include "shared/silhouette/silhouette_contour.h"

namespace silnet::node {

// Settings of the per-frame pipeline.
struct FrameProcessorOptions {
  std::string camera_id;
  uint32_t session = 0;
  SegmentationOptions segmentation;
  ContourOptions contour;
  // Extract and publish the full contour of frames whose index is a multiple of
  // `contour_every` (0 = never); flagged frames have none.
  int contour_every = 1;
  // A silhouette covering more than this fraction of the image is flagged saturated.
  double saturated_fraction = 0.9;
};

// The encoded outputs of one frame.
struct ProcessedFrame {
  FrameRecord hull;                    // HullFrame payload and header
  std::optional<FrameRecord> contour;  // Contour, on frames where one is due
  int foreground_pixels = 0;
  int hull_vertices = 0;
  cv::Mat mask;  // the silhouette (kept for stills and diagnostics)
};

// Turns captured frames into encoded silhouette samples. One instance per camera; frames in
// capture order.
class FrameProcessor {
 public:
  // `width` x `height` is the camera's frame size; every frame must have it. Throws
  // InputError for invalid options.
  FrameProcessor(const FrameProcessorOptions& options, int width, int height);

  // Processes one frame. A frame of the wrong size or type gives a flagged frame
  // (FRAME_BAD_INPUT) instead of an exception.
  ProcessedFrame Process(const CapturedFrame& frame);
  // A frame that carries only flags (dropped, unusable input): empty hull, no contour.
  ProcessedFrame Flagged(uint64_t frame_index, int64_t capture_time_ns, uint32_t flags) const;

  // Changes a setting by name: any segmentation setting, "contour_every" or
  // "contour_tolerance". Rebuilds the background model when a segmentation setting
  // changes. Returns false with a reason for unknown names or invalid values.
  bool SetParameter(const std::string& name, const std::string& value, std::string* error);
  const FrameProcessorOptions& options() const { return options_; }

 private:
  FrameRecord Header(uint64_t frame_index, int64_t capture_time_ns, uint32_t flags) const;

  FrameProcessorOptions options_;
  int width_;
  int height_;
  SilhouetteSegmenter segmenter_;
};

}  // namespace silnet::node

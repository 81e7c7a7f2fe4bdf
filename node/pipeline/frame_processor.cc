#include "node/pipeline/frame_processor.h"

#include <charconv>

#include "shared/silhouette/contour_codec.h"
#include "shared/silhouette/hull_codec.h"
#include "shared/util/check.h"
#include "silnet.h"

namespace silnet::node {

FrameProcessor::FrameProcessor(const FrameProcessorOptions& options, int width, int height)
    : options_(options), width_(width), height_(height), segmenter_(options.segmentation) {
  if (width <= 0 || height <= 0 || width > 4096 || height > 4096) {
    throw InputError("frame size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is out of range (1..4096)");
  }
  if (options.contour_every < 0) throw InputError("contour_every must be >= 0");
}

FrameRecord FrameProcessor::Header(uint64_t frame_index, int64_t capture_time_ns,
                                   uint32_t flags) const {
  FrameRecord record;
  record.camera_id = options_.camera_id;
  record.session = options_.session;
  record.frame_index = frame_index;
  record.capture_time_ns = capture_time_ns;
  record.width = static_cast<uint16_t>(width_);
  record.height = static_cast<uint16_t>(height_);
  record.flags = flags;
  return record;
}

ProcessedFrame FrameProcessor::Flagged(uint64_t frame_index, int64_t capture_time_ns,
                                       uint32_t flags) const {
  ProcessedFrame out;
  out.hull = Header(frame_index, capture_time_ns, flags | silnet_wire_FRAME_EMPTY);
  out.hull.payload = EncodeHull(HullPayload{});
  return out;
}

ProcessedFrame FrameProcessor::Process(const CapturedFrame& frame) {
  if (frame.image.cols != width_ || frame.image.rows != height_) {
    return Flagged(frame.frame_index, frame.capture_time_ns, silnet_wire_FRAME_BAD_INPUT);
  }
  Segmentation segmentation;
  try {
    segmentation = segmenter_.Segment(frame.image);
  } catch (const InputError&) {
    return Flagged(frame.frame_index, frame.capture_time_ns, silnet_wire_FRAME_BAD_INPUT);
  }
  ProcessedFrame out;
  MaskSummary summary;
  HullPayload payload;
  payload.hull = ComputeSilhouetteHull(segmentation.mask, &summary);
  payload.foreground_pixels = summary.foreground_pixels;
  uint32_t flags = 0;
  if (summary.foreground_pixels == 0) flags |= silnet_wire_FRAME_EMPTY;
  if (payload.hull.any_clipped()) flags |= silnet_wire_FRAME_CLIPPED;
  if (segmentation.cleanup.blobs > 1) flags |= silnet_wire_FRAME_MULTIPLE_BLOBS;
  if (summary.foreground_pixels > options_.saturated_fraction * width_ * height_) {
    flags |= silnet_wire_FRAME_SATURATED;
  }
  if (segmentation.warming_up) flags |= silnet_wire_FRAME_WARMUP;
  out.hull = Header(frame.frame_index, frame.capture_time_ns, flags);
  out.hull.payload = EncodeHull(payload);
  out.foreground_pixels = summary.foreground_pixels;
  out.hull_vertices = payload.hull.size();
  if (options_.contour_every > 0 &&
      frame.frame_index % static_cast<uint64_t>(options_.contour_every) == 0) {
    FrameRecord contour = Header(frame.frame_index, frame.capture_time_ns, flags);
    contour.payload = EncodeContours(ExtractContours(segmentation.mask, options_.contour));
    out.contour = std::move(contour);
  }
  out.mask = std::move(segmentation.mask);
  return out;
}

bool FrameProcessor::SetParameter(const std::string& name, const std::string& value,
                                  std::string* error) {
  if (name == "contour_every" || name == "contour_tolerance") {
    double number = 0.0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), number);
    if (ec != std::errc() || end != value.data() + value.size() || number < 0.0) {
      if (error != nullptr) *error = "'" + value + "' is not a valid value for " + name;
      return false;
    }
    if (name == "contour_every") {
      options_.contour_every = static_cast<int>(number);
    } else {
      options_.contour.tolerance_px = number;
    }
    return true;
  }
  SegmentationOptions changed = options_.segmentation;
  if (!changed.Set(name, value, error)) return false;
  if (const std::string reason = changed.Validate(); !reason.empty()) {
    if (error != nullptr) *error = reason;
    return false;
  }
  options_.segmentation = changed;
  segmenter_ = SilhouetteSegmenter(changed);
  return true;
}

}  // namespace silnet::node

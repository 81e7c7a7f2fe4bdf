#include "shared/silhouette/frame_sample_check.h"

#include "shared/silhouette/contour_codec.h"
#include "shared/silhouette/hull_codec.h"

namespace silnet {

std::string FindFrameSampleProblem(const FrameRecord& record, FramePayloadKind kind) {
  if (record.camera_id.empty()) return "empty camera id";
  for (char c : record.camera_id) {
    if (c < 33 || c > 126) return "camera id with unprintable characters";
  }
  if (record.width == 0 || record.height == 0) return "zero image size";
  std::string error;
  if (kind == FramePayloadKind::kContour) {
    SilhouetteContours contours;
    if (!DecodeContours(record.payload, record.width, record.height, &contours, &error))
      return error;
  } else {
    HullPayload payload;
    if (!DecodeHull(record.payload, record.width, record.height, &payload, &error)) return error;
  }
  return {};
}

}  // namespace silnet

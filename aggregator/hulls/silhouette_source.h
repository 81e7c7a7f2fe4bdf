#pragma once
// Where the hull job reads each camera's silhouettes: a dataset folder's mask images
// (<camera>/masks/%06d.png) or a session store's contours (the session logs `ingest` and
// the live job write: each camera's newest session, its Contour records rasterised to masks
// with their holes). Frames are numbered as the calibration numbers them: mask file index,
// or the node's frame index.

#include <filesystem>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"
#include "shared/io/frame_record.h"
#include "shared/silhouette/silhouette_contour.h"

namespace silnet::aggregator {

// Per-camera silhouettes by frame.
class SilhouetteSource {
 public:
  virtual ~SilhouetteSource() = default;
  // The cameras that have silhouettes, sorted.
  virtual std::vector<std::string> CameraIds() const = 0;
  // Frames 0..count-1 of `camera` may be asked for (0 if it has none). A session store may
  // lack some of them (nodes send a contour every few frames): Mask() then says so.
  virtual int FrameCount(const std::string& camera) const = 0;
  // `camera`'s silhouette of `frame` as a CV_8UC1 mask of the calibration's size. Throws
  // InputError if it is missing, unreadable, or of another size.
  virtual cv::Mat Mask(const CameraModel& camera, int frame) const = 0;
  // Where `camera`'s frame is read from, for messages.
  virtual std::string Where(const std::string& camera, int frame) const = 0;
  // The input folder.
  virtual const std::filesystem::path& root() const = 0;
};

// Opens a session store (session logs in `input` or `input`/sessions) or else a dataset
// folder. Throws InputError if a session log cannot be read.
std::unique_ptr<SilhouetteSource> OpenSilhouetteSource(const std::filesystem::path& input);

// The mask of a Contour record (the node's contour encoding) of `camera`. Throws InputError
// naming `where` if the record does not decode or is not of the calibration's size.
cv::Mat ContourRecordMask(const FrameRecord& record, const CameraModel& camera,
                          const std::string& where);

// Rasterises decoded contours into a `width` x `height` mask: a pixel is 255 iff its centre
// lies inside some polygon (inside its outer ring and outside its holes).
cv::Mat RasteriseContours(const SilhouetteContours& contours, int width, int height);

}  // namespace silnet::aggregator

#pragma once
// The input of the stereo job (thesis ch. 5-6): calibrated colour photographs of a still
// subject, each with its silhouette, all of one instant. Every loader (stills_folder.h,
// middlebury_dataset.h) gives this, so the stereo stages never see file layouts.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// Where a view's silhouette came from.
enum class MaskOrigin {
  kMaskFile,              // <camera>/masks/%06d.png
  kBackgroundDifference,  // the still against <camera>/background.png
                          // (node/segmentation/background_difference.h)
  kThreshold,             // thresholding a dark background (Middlebury)
};

// "mask file", "background difference" or "threshold".
std::string ToString(MaskOrigin source);

// One calibrated photograph with its silhouette.
struct StereoView {
  CameraModel camera;  // pinhole (zero distortion) unless the loader was asked to keep it
  cv::Mat image;       // CV_8UC3 BGR, camera.width x camera.height
  cv::Mat mask;        // CV_8UC1, 255 silhouette, 0 background, the image's size
  MaskOrigin silhouette_source = MaskOrigin::kMaskFile;
  size_t nonbinary_mask_pixels = 0;  // mask file pixels neither 0 nor 255 (thresholded at 128)
};

// The views a loader found usable, and what it reported on the way.
struct StereoViews {
  std::vector<StereoView> views;
  // One readable line per camera left out or input repaired ("cam03: no stills/000000.png,
  // left out"), in camera order.
  std::vector<std::string> warnings;

  // The cameras and masks of all views, in order (for the hull code).
  std::vector<CameraModel> Cameras() const;
  std::vector<cv::Mat> Masks() const;
};

}  // namespace silnet::aggregator

#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

std::string ToString(MaskOrigin source) {
  switch (source) {
    case MaskOrigin::kMaskFile:
      return "mask file";
    case MaskOrigin::kBackgroundDifference:
      return "background difference";
    case MaskOrigin::kThreshold:
      return "threshold";
  }
  return "unknown";
}

std::vector<CameraModel> StereoViews::Cameras() const {
  std::vector<CameraModel> cameras;
  cameras.reserve(views.size());
  for (const StereoView& view : views)
    cameras.push_back(view.camera);
  return cameras;
}

std::vector<cv::Mat> StereoViews::Masks() const {
  std::vector<cv::Mat> masks;
  masks.reserve(views.size());
  for (const StereoView& view : views)
    masks.push_back(view.mask);
  return masks;
}

}  // namespace silnet::aggregator

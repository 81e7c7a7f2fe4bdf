#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

std::string ToString(SilhouetteSource source) {
  switch (source) {
    case SilhouetteSource::kMaskFile:
      return "mask file";
    case SilhouetteSource::kBackgroundDifference:
      return "background difference";
    case SilhouetteSource::kThreshold:
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

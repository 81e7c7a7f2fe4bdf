#pragma once
// Removes lens distortion from a stereo view so the stereo stages can use pinhole cameras:
// image and mask are resampled (OpenCV initUndistortRectifyMap + remap) into the same K
// and size, so a pixel of the result is the pinhole projection K [R | t] X. The image is
// interpolated bilinearly; the mask is interpolated and thresholded at 128 (its outline
// moves by under half a pixel). Pixels whose source lies outside the original image become
// black image and background mask.

#include "aggregator/stereo/stereo_views.h"

namespace silnet::aggregator {

// The view with zero distortion; views without distortion are returned unchanged.
StereoView UndistortView(const StereoView& view);

}  // namespace silnet::aggregator

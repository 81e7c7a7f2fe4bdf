#pragma once
// Outline pixels a subject only partly covers. A pixel on a silhouette's outline mixes the
// subject's colour with the background's in proportion to how much of it the subject covers;
// the threshold of background difference takes it as soon as the mix differs from the
// background by a few digital numbers, so against a contrasting background the silhouette
// grows by a fraction of a pixel all round. Silhouettes elsewhere in silnet mean "the pixel's
// centre is inside the subject" (coverage above one half for a straight outline), and a
// silhouette too large by that band closes the narrow background gaps between limbs, which
// stereo under exact silhouette constraints then has to fill (docs/PERFORMANCE.md, issue 19).
// Here each outline pixel's coverage is estimated from its colour as the share of the way from
// the background's colour to the subject's colour nearby (the mean of the silhouette's pixels
// at least `interior_distance` inside the outline in a small window), and the pixel is dropped
// when that share is below one half.

#include <opencv2/core/mat.hpp>

namespace silnet::node {

// Settings of the coverage estimate.
struct OutlineCoverageOptions {
  int window_radius = 3;           // the subject's colour from a (2r+1)^2 window
  double interior_distance = 2.5;  // pixels at least this far inside the outline give it
  int min_interior_pixels = 3;     // fewer: the pixel is kept as it is
  // Below this colour distance between subject and background (digital numbers) the
  // estimate is noise: the pixel is kept as it is.
  double min_contrast = 24.0;
  double min_coverage = 0.5;
};

// Sets to 0 the pixels of `mask` (CV_8UC1, 255 silhouette) next to its background
// (4-neighbourhood) whose estimated coverage in `still` against `background` (CV_8UC3, the
// mask's size) is below options.min_coverage, and marks them 255 in `*trimmed` (CV_8UC1, the
// mask's size; may be null). Pixels of other values are left alone. One pass: the pixels
// uncovered by a drop are not looked at again. Returns how many were dropped.
int TrimPartlyCoveredOutline(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                             cv::Mat* trimmed = nullptr,
                             const OutlineCoverageOptions& options = {});

}  // namespace silnet::node

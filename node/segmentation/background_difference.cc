#include "node/segmentation/background_difference.h"

#include "node/segmentation/shadow_texture.h"
#include "shared/util/check.h"

namespace silnet::node {

BackgroundDifference SegmentAgainstBackground(const cv::Mat& still, const cv::Mat& background,
                                              const BackgroundDifferenceOptions& options) {
  if (still.type() != CV_8UC3 || background.type() != CV_8UC3)
    throw InputError("background difference needs 8-bit BGR images");
  if (still.size() != background.size()) {
    throw InputError("the background is " + std::to_string(background.cols) + "x" +
                     std::to_string(background.rows) + ", the still " + std::to_string(still.cols) +
                     "x" + std::to_string(still.rows));
  }
  const node::SegmentationOptions& o = options.node;
  const float min2 = static_cast<float>(o.min_difference * o.min_difference);
  BackgroundDifference result;
  result.mask = cv::Mat(still.size(), CV_8UC1, cv::Scalar(0));
  cv::Mat ratio(still.size(), CV_32F, cv::Scalar(0.0f));  // of the shadow candidates
  bool candidates = false;
  for (int y = 0; y < still.rows; ++y) {
    const uint8_t* in = still.ptr<uint8_t>(y);
    const uint8_t* bg = background.ptr<uint8_t>(y);
    uint8_t* out = result.mask.ptr<uint8_t>(y);
    for (int x = 0; x < still.cols; ++x) {
      float i[3], b[3];
      for (int c = 0; c < 3; ++c) {
        i[c] = static_cast<float>(in[3 * x + c]);
        b[c] = static_cast<float>(bg[3 * x + c]);
      }
      const float d0 = i[0] - b[0], d1 = i[1] - b[1], d2 = i[2] - b[2];
      if (d0 * d0 + d1 * d1 + d2 * d2 <= min2) continue;
      out[x] = 255;
      if (!o.suppress_shadows) continue;
      if (const float alpha = ShadowRatio(i, b, o); alpha > 0.0f) {
        out[x] = 128;
        ratio.at<float>(y, x) = alpha;
        candidates = true;
      }
    }
  }
  if (candidates) ResolveShadowCandidates(result.mask, ratio, o.shadow_texture);
  result.cleanup = node::CleanMask(&result.mask, o);
  if (options.fill_camouflaged_holes) {
    CamouflageOptions camouflage = options.camouflage;
    camouflage.threshold = o.min_difference;
    result.camouflaged_holes_filled =
        FillCamouflagedHoles(&result.mask, still, background, camouflage);
  }
  cv::Mat trimmed;
  if (options.trim_partly_covered_outline) {
    result.outline_pixels_trimmed =
        TrimPartlyCoveredOutline(&result.mask, still, background, &trimmed, options.outline);
  }
  if (options.mark_weak_silhouette) {
    result.weak_pixels = MarkWeakSilhouette(&result.mask, still, background, o, options.weak,
                                            trimmed.empty() ? nullptr : &trimmed);
  }
  return result;
}

}  // namespace silnet::node

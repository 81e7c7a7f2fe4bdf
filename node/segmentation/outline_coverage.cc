#include "node/segmentation/outline_coverage.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace silnet::node {

int TrimPartlyCoveredOutline(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                             cv::Mat* trimmed, const OutlineCoverageOptions& options) {
  // Distance to the nearest background pixel: 1 exactly next to one (4-neighbourhood).
  cv::Mat inside;
  cv::distanceTransform(*mask != 0, inside, cv::DIST_L2, cv::DIST_MASK_5);
  const int r = options.window_radius;
  const float interior = static_cast<float>(options.interior_distance);
  const double min_contrast2 = options.min_contrast * options.min_contrast;
  std::vector<cv::Point> drop;
  for (int y = 0; y < mask->rows; ++y) {
    for (int x = 0; x < mask->cols; ++x) {
      if (mask->at<uint8_t>(y, x) != 255 || inside.at<float>(y, x) > 1.0f) continue;
      double subject[3] = {0.0, 0.0, 0.0};
      int count = 0;
      for (int v = std::max(0, y - r); v <= std::min(mask->rows - 1, y + r); ++v) {
        for (int u = std::max(0, x - r); u <= std::min(mask->cols - 1, x + r); ++u) {
          if (mask->at<uint8_t>(v, u) != 255 || inside.at<float>(v, u) < interior) continue;
          const cv::Vec3b& c = still.at<cv::Vec3b>(v, u);
          for (int k = 0; k < 3; ++k)
            subject[k] += c[k];
          ++count;
        }
      }
      if (count < options.min_interior_pixels) continue;
      const cv::Vec3b& seen = still.at<cv::Vec3b>(y, x);
      const cv::Vec3b& empty = background.at<cv::Vec3b>(y, x);
      double contrast2 = 0.0, along = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double to_subject = subject[k] / count - empty[k];
        contrast2 += to_subject * to_subject;
        along += to_subject * (static_cast<double>(seen[k]) - empty[k]);
      }
      if (contrast2 < min_contrast2) continue;
      if (along / contrast2 < options.min_coverage) drop.emplace_back(x, y);
    }
  }
  if (trimmed) *trimmed = cv::Mat(mask->size(), CV_8UC1, cv::Scalar(0));
  for (const cv::Point& p : drop) {
    mask->at<uint8_t>(p) = 0;
    if (trimmed) trimmed->at<uint8_t>(p) = 255;
  }
  return static_cast<int>(drop.size());
}

}  // namespace silnet::node

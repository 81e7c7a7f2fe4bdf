#include "node/segmentation/weak_silhouette.h"

#include <opencv2/imgproc.hpp>
#include <vector>

namespace silnet::node {

int MarkWeakSilhouette(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                       const WeakSilhouetteOptions& options) {
  cv::Mat photo, scene;
  cv::GaussianBlur(still, photo, cv::Size(3, 3), 0);
  cv::GaussianBlur(background, scene, cv::Size(3, 3), 0);
  const double min2 = options.min_difference * options.min_difference;
  const double chroma2 = options.shadow_chroma * options.shadow_chroma;
  cv::Mat candidates(mask->size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < mask->rows; ++y) {
    const uint8_t* in = mask->ptr<uint8_t>(y);
    const auto* p = photo.ptr<cv::Vec3b>(y);
    const auto* b = scene.ptr<cv::Vec3b>(y);
    uint8_t* out = candidates.ptr<uint8_t>(y);
    for (int x = 0; x < mask->cols; ++x) {
      if (in[x] != 0) continue;
      const cv::Vec3d i = p[x], g = b[x];
      const cv::Vec3d d = i - g;
      if (d.dot(d) <= min2) continue;
      const double gg = g.dot(g);
      const double alpha = gg > 1.0 ? i.dot(g) / gg : 1.0;
      const cv::Vec3d c = i - alpha * g;
      const bool shadow = alpha >= options.shadow_min_ratio && alpha <= options.shadow_max_ratio &&
                          c.dot(c) < chroma2 * alpha * alpha * gg;
      if (!shadow) out[x] = 255;
    }
  }
  // Keep the candidates connected to the silhouette.
  cv::Mat labels;
  const int count = cv::connectedComponents((*mask == 255) | candidates, labels, 8, CV_32S);
  std::vector<bool> touches(static_cast<size_t>(count), false);
  for (int y = 0; y < mask->rows; ++y) {
    const uint8_t* in = mask->ptr<uint8_t>(y);
    const int* label = labels.ptr<int>(y);
    for (int x = 0; x < mask->cols; ++x) {
      if (in[x] == 255) touches[static_cast<size_t>(label[x])] = true;
    }
  }
  int marked = 0;
  for (int y = 0; y < mask->rows; ++y) {
    uint8_t* out = mask->ptr<uint8_t>(y);
    const uint8_t* candidate = candidates.ptr<uint8_t>(y);
    const int* label = labels.ptr<int>(y);
    for (int x = 0; x < mask->cols; ++x) {
      if (candidate[x] != 0 && touches[static_cast<size_t>(label[x])]) {
        out[x] = kWeakSilhouette;
        ++marked;
      }
    }
  }
  return marked;
}

}  // namespace silnet::node

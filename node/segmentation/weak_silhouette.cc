#include "node/segmentation/weak_silhouette.h"

#include <opencv2/imgproc.hpp>
#include <vector>

#include "node/segmentation/shadow_texture.h"

namespace silnet::node {

int MarkWeakSilhouette(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                       const SegmentationOptions& segmentation,
                       const WeakSilhouetteOptions& options) {
  cv::Mat photo, scene;
  cv::GaussianBlur(still, photo, cv::Size(3, 3), 0);
  cv::GaussianBlur(background, scene, cv::Size(3, 3), 0);
  const double min2 = options.min_difference * options.min_difference;
  cv::Mat candidates(mask->size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < mask->rows; ++y) {
    const uint8_t* in = mask->ptr<uint8_t>(y);
    const auto* p = photo.ptr<cv::Vec3b>(y);
    const auto* b = scene.ptr<cv::Vec3b>(y);
    uint8_t* out = candidates.ptr<uint8_t>(y);
    for (int x = 0; x < mask->cols; ++x) {
      if (in[x] != 0) continue;
      const double i[3] = {static_cast<double>(p[x][0]), static_cast<double>(p[x][1]),
                           static_cast<double>(p[x][2])};
      const double g[3] = {static_cast<double>(b[x][0]), static_cast<double>(b[x][1]),
                           static_cast<double>(b[x][2])};
      double d2 = 0;
      for (int c = 0; c < 3; ++c)
        d2 += (i[c] - g[c]) * (i[c] - g[c]);
      if (d2 > min2 && ShadowRatio(i, g, segmentation) == 0.0) out[x] = 255;
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

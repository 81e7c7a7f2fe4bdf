#include "node/segmentation/weak_silhouette.h"

#include <opencv2/imgproc.hpp>
#include <vector>

#include "node/segmentation/shadow_texture.h"

namespace silnet::node {

int MarkWeakSilhouette(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                       const SegmentationOptions& segmentation,
                       const WeakSilhouetteOptions& options, const cv::Mat* excluded) {
  // Pixels outside the silhouette that differ from the background by more than the
  // segmentation's threshold (the clean-up's removals, a thin part it opened away) are
  // candidates as they are. The others are judged after a blur over themselves only
  // (normalised convolution): a plain blur would spread the silhouette's own difference, or a
  // strong pixel's, one pixel out, marking a band along every contrasting outline.
  const double strong2 = segmentation.min_difference * segmentation.min_difference;
  cv::Mat strong(mask->size(), CV_8UC1, cv::Scalar(0));
  cv::Mat faint(mask->size(), CV_32F, cv::Scalar(0.0f));  // the blur's weights
  for (int y = 0; y < mask->rows; ++y) {
    const uint8_t* in = mask->ptr<uint8_t>(y);
    const auto* p = still.ptr<cv::Vec3b>(y);
    const auto* b = background.ptr<cv::Vec3b>(y);
    for (int x = 0; x < mask->cols; ++x) {
      if (in[x] == 255) continue;
      double i[3], g[3], d2 = 0.0;
      for (int c = 0; c < 3; ++c) {
        i[c] = p[x][c];
        g[c] = b[x][c];
        d2 += (i[c] - g[c]) * (i[c] - g[c]);
      }
      if (d2 > strong2) {
        if (ShadowRatio(i, g, segmentation) == 0.0) strong.at<uint8_t>(y, x) = 255;
      } else {
        faint.at<float>(y, x) = 1.0f;
      }
    }
  }
  const auto blur_faint = [&](const cv::Mat& image) {
    cv::Mat values, weights3, blurred;
    image.convertTo(values, CV_32FC3);
    cv::merge(std::vector<cv::Mat>{faint, faint, faint}, weights3);
    cv::GaussianBlur(values.mul(weights3), blurred, cv::Size(3, 3), 0);
    return blurred;
  };
  const cv::Mat photo = blur_faint(still), scene = blur_faint(background);
  cv::Mat weight;
  cv::GaussianBlur(faint, weight, cv::Size(3, 3), 0);
  const double min2 = options.min_difference * options.min_difference;
  cv::Mat candidates(mask->size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < mask->rows; ++y) {
    const uint8_t* in = mask->ptr<uint8_t>(y);
    const uint8_t* skip = excluded ? excluded->ptr<uint8_t>(y) : nullptr;
    const uint8_t* clear = strong.ptr<uint8_t>(y);
    const auto* p = photo.ptr<cv::Vec3f>(y);
    const auto* b = scene.ptr<cv::Vec3f>(y);
    const float* w = weight.ptr<float>(y);
    const float* own = faint.ptr<float>(y);
    uint8_t* out = candidates.ptr<uint8_t>(y);
    for (int x = 0; x < mask->cols; ++x) {
      if (in[x] != 0 || (skip && skip[x] != 0)) continue;
      if (clear[x] != 0) {
        out[x] = 255;
        continue;
      }
      if (own[x] == 0.0f) continue;  // a shadow-like strong difference
      double i[3], g[3], d2 = 0.0;
      for (int c = 0; c < 3; ++c) {
        i[c] = p[x][c] / w[x];
        g[c] = b[x][c] / w[x];
        d2 += (i[c] - g[c]) * (i[c] - g[c]);
      }
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

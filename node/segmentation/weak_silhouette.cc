#include "node/segmentation/weak_silhouette.h"

#include <opencv2/imgproc.hpp>
#include <vector>

#include "node/segmentation/shadow_texture.h"

namespace silnet::node {

namespace {

// The pixels outside the silhouette of `mask` that differ from the background by more than
// the segmentation's threshold and not like a shadow (`strong`, 0/255), and those that differ
// by less (`faint`, weights 0/1 of the blur).
void SplitByDifference(const cv::Mat& mask, const cv::Mat& still, const cv::Mat& background,
                       const SegmentationOptions& segmentation, cv::Mat* strong, cv::Mat* faint) {
  const double strong2 = segmentation.min_difference * segmentation.min_difference;
  *strong = cv::Mat(mask.size(), CV_8UC1, cv::Scalar(0));
  *faint = cv::Mat(mask.size(), CV_32F, cv::Scalar(0.0f));
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* in = mask.ptr<uint8_t>(y);
    const auto* p = still.ptr<cv::Vec3b>(y);
    const auto* b = background.ptr<cv::Vec3b>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (in[x] == 255) continue;
      double i[3], g[3], d2 = 0.0;
      for (int c = 0; c < 3; ++c) {
        i[c] = p[x][c];
        g[c] = b[x][c];
        d2 += (i[c] - g[c]) * (i[c] - g[c]);
      }
      if (d2 <= strong2) {
        faint->at<float>(y, x) = 1.0f;
      } else if (ShadowRatio(i, g, segmentation) == 0.0) {
        strong->at<uint8_t>(y, x) = 255;
      }
    }
  }
}

// `image` (CV_8UC3) blurred 3x3 over the pixels of weight 1 in `faint` only, not yet divided
// by the blurred weights (CV_32FC3).
cv::Mat BlurOver(const cv::Mat& image, const cv::Mat& faint) {
  cv::Mat values, weights, blurred;
  image.convertTo(values, CV_32FC3);
  cv::merge(std::vector<cv::Mat>{faint, faint, faint}, weights);
  cv::GaussianBlur(values.mul(weights), blurred, cv::Size(3, 3), 0);
  return blurred;
}

}  // namespace

int MarkWeakSilhouette(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                       const SegmentationOptions& segmentation,
                       const WeakSilhouetteOptions& options, const cv::Mat* excluded) {
  // Strong pixels outside the silhouette (the clean-up's removals, a thin part it opened away)
  // are candidates as they are. Faint ones are judged after a blur over faint pixels only
  // (normalised convolution): a plain blur would spread the silhouette's own difference, or a
  // strong pixel's, one pixel out, marking a band along every contrasting outline.
  cv::Mat strong, faint, weight;
  SplitByDifference(*mask, still, background, segmentation, &strong, &faint);
  const cv::Mat photo = BlurOver(still, faint), scene = BlurOver(background, faint);
  cv::GaussianBlur(faint, weight, cv::Size(3, 3), 0);
  const double min2 = options.min_difference * options.min_difference;
  cv::Mat candidates(mask->size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < mask->rows; ++y) {
    const uint8_t* in = mask->ptr<uint8_t>(y);
    const uint8_t* skip = excluded ? excluded->ptr<uint8_t>(y) : nullptr;
    const uint8_t* clear = strong.ptr<uint8_t>(y);
    const float* own = faint.ptr<float>(y);
    const auto* p = photo.ptr<cv::Vec3f>(y);
    const auto* b = scene.ptr<cv::Vec3f>(y);
    const float* w = weight.ptr<float>(y);
    uint8_t* out = candidates.ptr<uint8_t>(y);
    for (int x = 0; x < mask->cols; ++x) {
      if (in[x] != 0 || (skip && skip[x] != 0)) continue;
      if (clear[x] != 0) {
        out[x] = 255;
        continue;
      }
      if (own[x] == 0.0f) continue;  // a strong difference like a shadow's
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

#include "node/segmentation/camouflaged_holes.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace silnet::node {
namespace {

// Sums over one hole of grey photo a, grey background b and the squared colour distance d2.
struct HoleSums {
  double n = 0, a = 0, b = 0, aa = 0, bb = 0, ab = 0, d2 = 0, shadow = 0;

  double Correlation() const {
    const double cov = ab / n - (a / n) * (b / n);
    const double va = aa / n - (a / n) * (a / n), vb = bb / n - (b / n) * (b / n);
    return va > 0 && vb > 0 ? cov / std::sqrt(va * vb) : 0.0;
  }
  double RmsDistance() const { return std::sqrt(d2 / n); }
};

double SquaredDistance(const cv::Vec3b& p, const cv::Vec3b& q) {
  double sum = 0;
  for (int c = 0; c < 3; ++c) {
    const double d = static_cast<double>(p[c]) - q[c];
    sum += d * d;
  }
  return sum;
}

}  // namespace

int FillCamouflagedHoles(cv::Mat* mask, const cv::Mat& still, const cv::Mat& background,
                         const CamouflageOptions& options) {
  cv::Mat labels;
  const int count = cv::connectedComponents(*mask == 0, labels, 4, CV_32S);
  if (count < 2) return 0;
  // Background regions reaching the border are the scene around the subject.
  std::vector<bool> outside(static_cast<size_t>(count), false);
  const auto mark = [&](int y, int x) {
    outside[static_cast<size_t>(labels.at<int>(y, x))] = true;
  };
  for (int x = 0; x < labels.cols; ++x) {
    mark(0, x);
    mark(labels.rows - 1, x);
  }
  for (int y = 0; y < labels.rows; ++y) {
    mark(y, 0);
    mark(y, labels.cols - 1);
  }
  // Bays: background pixels reaching the scene that closing the silhouette would cover.
  cv::Mat bays;
  int bay_count = 0;
  const int radius = static_cast<int>(
      std::lround(options.bay_radius_fraction * std::hypot(mask->cols, mask->rows)));
  if (radius > 0) {
    cv::Mat closed;
    cv::morphologyEx(
        *mask, closed, cv::MORPH_CLOSE,
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
    bay_count = cv::connectedComponents((closed != 0) & (*mask == 0), bays, 4, CV_32S);
  }
  // Candidates: the enclosed holes (their background label) and the bays (count + bay label).
  const auto candidate = [&](int y, int x) -> int {
    const int l = labels.at<int>(y, x);
    if (!outside[static_cast<size_t>(l)]) return l;
    if (bay_count > 1) {
      const int b = bays.at<int>(y, x);
      if (b > 0) return count + b;
    }
    return -1;
  };
  std::vector<HoleSums> holes(static_cast<size_t>(count + std::max(bay_count, 1)));
  const double threshold2 = 4.0 * options.threshold * options.threshold;
  std::vector<float> noise;
  for (int y = 0; y < labels.rows; ++y) {
    const uint8_t* in = mask->ptr<uint8_t>(y);
    const auto* photo = still.ptr<cv::Vec3b>(y);
    const auto* scene = background.ptr<cv::Vec3b>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (in[x] != 0) continue;
      const int c = candidate(y, x);
      const double d2 = SquaredDistance(photo[x], scene[x]);
      if (c < 0) {
        if (((x | y) & 1) == 0) noise.push_back(static_cast<float>(std::sqrt(d2)));
        continue;
      }
      const double a = (photo[x][0] + photo[x][1] + photo[x][2]) / 3.0;
      const double b = (scene[x][0] + scene[x][1] + scene[x][2]) / 3.0;
      HoleSums& h = holes[static_cast<size_t>(c)];
      h.n += 1;
      h.a += a;
      h.b += b;
      h.aa += a * a;
      h.bb += b * b;
      h.ab += a * b;
      h.d2 += d2;
      if (d2 > threshold2) h.shadow += 1;
    }
  }
  if (noise.empty()) return 0;
  std::nth_element(noise.begin(), noise.begin() + static_cast<long>(noise.size() / 2), noise.end());
  const double typical = std::max(1.0, static_cast<double>(noise[noise.size() / 2]));
  std::vector<bool> fill(holes.size(), false);
  int filled = 0;
  for (size_t c = 0; c < holes.size(); ++c) {
    const HoleSums& h = holes[c];
    if (h.n < options.min_area) continue;
    if (h.shadow <= options.max_shadow_share * h.n && h.Correlation() < options.max_correlation &&
        h.RmsDistance() > options.min_difference_over_noise * typical) {
      fill[c] = true;
      ++filled;
    }
  }
  if (filled == 0) return 0;
  for (int y = 0; y < labels.rows; ++y) {
    uint8_t* out = mask->ptr<uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (out[x] != 0) continue;
      const int c = candidate(y, x);
      if (c >= 0 && fill[static_cast<size_t>(c)]) out[x] = 255;
    }
  }
  return filled;
}

}  // namespace silnet::node

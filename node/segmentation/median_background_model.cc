#include "node/segmentation/median_background_model.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "node/segmentation/shadow_texture.h"
#include "shared/util/check.h"

namespace silnet::node {
namespace {

constexpr float kInitialVariance = 3.0f * 9.0f;  // 3 channels x (3 DN)^2
constexpr float kMinimumVariance = 3.0f * 1.0f;

// Comparators of Batcher's odd-even merge sort for n elements (the network for the next
// power of two, without comparators that touch elements beyond n).
std::vector<std::pair<int, int>> SortingNetwork(int n) {
  int size = 1;
  while (size < n)
    size *= 2;
  std::vector<std::pair<int, int>> network;
  for (int p = 1; p < size; p *= 2) {
    for (int k = p; k >= 1; k /= 2) {
      for (int j = k % p; j + k < size; j += 2 * k) {
        for (int i = 0; i < std::min(k, size - j - k); ++i) {
          const int a = i + j, b = i + j + k;
          if ((a / (2 * p)) == (b / (2 * p)) && b < n) network.emplace_back(a, b);
        }
      }
    }
  }
  return network;
}

// lo[i], hi[i] = min, max of the pair, element-wise over two distinct buffers.
void CompareExchange(uint8_t* __restrict lo, uint8_t* __restrict hi, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    const uint8_t u = lo[i], v = hi[i];
    lo[i] = u < v ? u : v;
    hi[i] = u < v ? v : u;
  }
}

}  // namespace

MedianBackgroundModel::MedianBackgroundModel(const SegmentationOptions& options)
    : options_(options), network_(SortingNetwork(options.median_samples)) {}

void MedianBackgroundModel::AddSample(const cv::Mat& frame, double gain,
                                      const cv::Mat& foreground) {
  cv::Mat sample;
  frame.convertTo(sample, CV_8UC3, 1.0 / gain);
  // Foreground and a margin around it do not count as background observations.
  cv::Mat background(frame.size(), CV_8UC3, cv::Scalar::all(1));
  if (!foreground.empty()) {
    cv::Mat grown;
    cv::dilate(foreground, grown, cv::Mat(), cv::Point(-1, -1), 2);
    background.setTo(cv::Scalar::all(0), grown);
  }
  if (window_.size() < static_cast<size_t>(options_.median_samples)) {
    window_.push_back(sample);
    seen_background_.push_back(background);
  } else {
    window_[next_slot_] = sample;
    seen_background_[next_slot_] = background;
  }
  next_slot_ = (next_slot_ + 1) % static_cast<size_t>(options_.median_samples);
}

void MedianBackgroundModel::RecomputeRows(int first, int last) {
  if (last <= first) return;
  const size_t count = window_.size();
  const int enough = std::max(3, static_cast<int>(count + 1) / 2);
  const size_t width = static_cast<size_t>(background_.cols) * 3;
  const size_t values = width * static_cast<size_t>(last - first);
  // Observations a pixel saw as background, per channel byte, over the band.
  std::vector<uint8_t> valid_count(values, 0);
  for (size_t s = 0; s < count; ++s) {
    for (int y = first; y < last; ++y) {
      const uint8_t* seen = seen_background_[s].ptr<uint8_t>(y);
      uint8_t* c = valid_count.data() + static_cast<size_t>(y - first) * width;
      for (size_t x = 0; x < width; ++x)
        c[x] = static_cast<uint8_t>(c[x] + seen[x]);
    }
  }
  // One lane of values per sample. Where enough background observations exist, the others
  // are replaced by 0 and 255 alternately, which leaves the median of the rest in the middle.
  lanes_.resize(count);
  std::vector<uint8_t> invalid_seen(values, 0);
  for (size_t s = 0; s < count; ++s) {
    lanes_[s].resize(values);
    uint8_t* lane = lanes_[s].data();
    for (int y = first; y < last; ++y) {
      const size_t offset = static_cast<size_t>(y - first) * width;
      const uint8_t* sample = window_[s].ptr<uint8_t>(y);
      const uint8_t* seen = seen_background_[s].ptr<uint8_t>(y);
      for (size_t x = 0; x < width; ++x) {
        const bool replace = seen[x] == 0 && valid_count[offset + x] >= enough;
        const uint8_t filler = (invalid_seen[offset + x] & 1) ? 255 : 0;
        lane[offset + x] = replace ? filler : sample[x];
        invalid_seen[offset + x] =
            static_cast<uint8_t>(invalid_seen[offset + x] + (replace ? 1 : 0));
      }
    }
  }
  // Sort the lanes element-wise (vectorisable min/max), or fall back to nth_element for a
  // window that is still filling.
  size_t middle_lane = count / 2;
  if (count == static_cast<size_t>(options_.median_samples)) {
    for (const auto& [a, b] : network_) {
      CompareExchange(lanes_[static_cast<size_t>(a)].data(), lanes_[static_cast<size_t>(b)].data(),
                      values);
    }
  } else {
    uint8_t column[64];
    for (size_t x = 0; x < values; ++x) {
      for (size_t s = 0; s < count; ++s)
        column[s] = lanes_[s][x];
      std::nth_element(column, column + middle_lane, column + count);
      lanes_[middle_lane][x] = column[middle_lane];
    }
  }
  const uint8_t* median = lanes_[middle_lane].data();
  for (int y = first; y < last; ++y) {
    float* out = background_.ptr<float>(y);
    const uint8_t* m = median + static_cast<size_t>(y - first) * width;
    for (size_t x = 0; x < width; ++x)
      out[x] = m[x];
  }
}

double MedianBackgroundModel::EstimateGain(const cv::Mat& frame) const {
  // Ratio of brightness sums over a sparse grid of pixels that were background last frame.
  double frame_sum = 0.0, background_sum = 0.0;
  for (int y = 2; y < frame.rows; y += 8) {
    const auto* in = frame.ptr<uint8_t>(y);
    const auto* bg = background_.ptr<float>(y);
    const auto* mask = last_mask_.empty() ? nullptr : last_mask_.ptr<uint8_t>(y);
    for (int x = 3; x < frame.cols; x += 8) {
      if (mask != nullptr && mask[x] != 0) continue;
      frame_sum += in[3 * x] + in[3 * x + 1] + in[3 * x + 2];
      background_sum += bg[3 * x] + bg[3 * x + 1] + bg[3 * x + 2];
    }
  }
  if (background_sum <= 0.0) return 1.0;
  return std::clamp(frame_sum / background_sum, 0.5, 2.0);
}

cv::Mat MedianBackgroundModel::Classify(const cv::Mat& frame, bool* warming_up) {
  SILNET_CHECK_MSG(frame.type() == CV_8UC3, "the median model segments BGR frames");
  if (!background_.empty() && frame.size() != background_.size()) {
    throw InputError("frame size changed from " + std::to_string(background_.cols) + "x" +
                     std::to_string(background_.rows) + " to " + std::to_string(frame.cols) + "x" +
                     std::to_string(frame.rows));
  }
  if (background_.empty()) {
    background_ = cv::Mat(frame.size(), CV_32FC3, cv::Scalar::all(0));
    variance_ = cv::Mat(frame.size(), CV_32F, cv::Scalar(kInitialVariance));
  }
  const bool full = window_.size() == static_cast<size_t>(options_.median_samples);
  gain_ = window_.empty() ? 1.0 : EstimateGain(frame);
  const long stride = options_.median_stride;
  if (frames_seen_ % stride == 0) {
    AddSample(frame, gain_, last_mask_);
    // While the window fills, the whole median follows every new sample.
    if (!full) RecomputeRows(0, frame.rows);
  }
  if (full) {
    // A band of rows per frame: the whole image once per sampling period.
    const int band = (frame.rows + static_cast<int>(stride) - 1) / static_cast<int>(stride);
    const int first = static_cast<int>(frames_seen_ % stride) * band;
    RecomputeRows(std::min(first, frame.rows), std::min(first + band, frame.rows));
  }
  ++frames_seen_;
  *warming_up = window_.size() < static_cast<size_t>(options_.median_samples);
  cv::Mat mask(frame.size(), CV_8U, cv::Scalar(0));
  if (window_.size() < 3) {
    last_mask_ = mask;
    return mask;
  }

  const float gain = static_cast<float>(gain_);
  const float k2 = static_cast<float>(options_.threshold_sigmas * options_.threshold_sigmas);
  const float min2 = static_cast<float>(options_.min_difference * options_.min_difference);
  const bool shadows = options_.suppress_shadows;
  // The variance learns only from a trained model, and grows by at most 3x per observation.
  const float rate = *warming_up ? 0.0f : static_cast<float>(options_.learning_rate);
  // Pass 1: colour distance to the background; candidates that look like shadows get their
  // brightness ratio recorded for the texture test. 255 = foreground, 128 = shadow-like.
  cv::Rect shadow_box;
  for (int y = 0; y < frame.rows; ++y) {
    const uint8_t* in = frame.ptr<uint8_t>(y);
    const float* bg = background_.ptr<float>(y);
    float* var = variance_.ptr<float>(y);
    uint8_t* out = mask.ptr<uint8_t>(y);
    int row_first = -1, row_last = -1;
    for (int x = 0; x < frame.cols; ++x) {
      float i[3], b[3];
      for (int c = 0; c < 3; ++c) {
        i[c] = static_cast<float>(in[3 * x + c]);
        b[c] = gain * bg[3 * x + c];
      }
      const float d0 = i[0] - b[0], d1 = i[1] - b[1], d2 = i[2] - b[2];
      const float distance2 = d0 * d0 + d1 * d1 + d2 * d2;
      if (distance2 <= std::max(k2 * var[x], min2)) {
        var[x] = std::max(kMinimumVariance,
                          var[x] + rate * (std::min(distance2, 3.0f * var[x]) - var[x]));
        continue;
      }
      out[x] = 255;
      if (shadows && ShadowRatio(i, b, options_) > 0.0f) {
        out[x] = 128;
        if (row_first < 0) row_first = x;
        row_last = x;
      }
    }
    if (row_first >= 0) shadow_box |= cv::Rect(row_first, y, row_last - row_first + 1, 1);
  }
  // Pass 2: a shadow keeps the background's texture (shadow_texture.h).
  if (shadow_box.area() > 0) {
    const int margin = 2;
    const cv::Rect box = cv::Rect(shadow_box.x - margin, shadow_box.y - margin,
                                  shadow_box.width + 2 * margin, shadow_box.height + 2 * margin) &
                         cv::Rect(0, 0, frame.cols, frame.rows);
    // Brightness ratios of the shadow-like pixels (0 elsewhere: they carry no weight).
    cv::Mat ratio(box.size(), CV_32F, cv::Scalar(0.0f));
    for (int y = 0; y < box.height; ++y) {
      const uint8_t* in = frame.ptr<uint8_t>(y + box.y) + 3 * box.x;
      const float* bg = background_.ptr<float>(y + box.y) + 3 * box.x;
      const uint8_t* m = mask.ptr<uint8_t>(y + box.y) + box.x;
      float* r = ratio.ptr<float>(y);
      for (int x = 0; x < box.width; ++x) {
        if (m[x] != 128) continue;
        const float b0 = gain * bg[3 * x], b1 = gain * bg[3 * x + 1], b2 = gain * bg[3 * x + 2];
        r[x] = (in[3 * x] * b0 + in[3 * x + 1] * b1 + in[3 * x + 2] * b2) /
               (b0 * b0 + b1 * b1 + b2 * b2);
      }
    }
    ResolveShadowCandidates(mask(box), ratio, options_.shadow_texture);
  }
  last_mask_ = mask;
  return mask;
}

}  // namespace silnet::node

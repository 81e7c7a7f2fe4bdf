#include "aggregator/stereo/epipolar_ncc_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

constexpr int kMaxWindow = 31;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Share of the window x pixels around integer pixel (x, y) inside the silhouette.
double SilhouetteShare(const NccImage& image, int x, int y, int half) {
  const int x0 = std::max(0, x - half), y0 = std::max(0, y - half);
  const int x1 = std::min(image.mask.cols, x + half + 1),
            y1 = std::min(image.mask.rows, y + half + 1);
  if (x1 <= x0 || y1 <= y0) return 0.0;
  const cv::Mat& s = image.mask_integral;
  const int inside = s.at<int>(y1, x1) - s.at<int>(y0, x1) - s.at<int>(y1, x0) + s.at<int>(y0, x0);
  const int side = 2 * half + 1;
  return static_cast<double>(inside) / static_cast<double>(side * side);
}

}  // namespace

std::string EpipolarNccOptions::Validate() const {
  if (window < 3 || window > kMaxWindow || window % 2 == 0)
    return "NCC window must be odd and within 3..31 pixels";
  if (!(min_ncc >= -1.0 && min_ncc <= 1.0)) return "min_ncc must lie in [-1, 1]";
  if (!(step_px > 0.0 && step_px <= 4.0)) return "step_px must lie in (0, 4] pixels";
  if (!(min_std >= 0.0)) return "min_std must not be negative";
  if (!(min_window_in_silhouette >= 0.0 && min_window_in_silhouette <= 1.0))
    return "min_window_in_silhouette must lie in [0, 1]";
  if (max_matches < 0) return "max_matches must not be negative (0 = all)";
  return {};
}

NccImage NccImage::FromView(const StereoView& view, bool colour) {
  SILNET_CHECK(view.image.type() == CV_8UC3 && view.mask.type() == CV_8UC1);
  SILNET_CHECK(view.image.size() == view.mask.size());
  NccImage out;
  if (colour) {
    view.image.convertTo(out.pixels, CV_32FC3);
    out.channels = 3;
  } else {
    cv::Mat grey;
    cv::cvtColor(view.image, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(out.pixels, CV_32FC1);
    out.channels = 1;
  }
  out.mask = view.mask;
  cv::Mat binary = view.mask != 0;
  binary /= 255;
  cv::integral(binary, out.mask_integral, CV_32S);
  return out;
}

bool ReferenceWindow(const NccImage& image, int x, int y, const EpipolarNccOptions& options,
                     std::vector<float>* window) {
  const int half = options.window / 2, ch = image.channels;
  if (x - half < 0 || y - half < 0 || x + half >= image.pixels.cols ||
      y + half >= image.pixels.rows)
    return false;
  const int row = options.window * ch;
  const size_t count = static_cast<size_t>(row) * static_cast<size_t>(options.window);
  window->resize(count);
  float* out = window->data();
  double sum = 0.0;
  for (int j = 0; j < options.window; ++j) {
    const float* p = image.pixels.ptr<float>(y - half + j) + (x - half) * ch;
    for (int e = 0; e < row; ++e) {
      out[j * row + e] = p[e];
      sum += p[e];
    }
  }
  const double mean = sum / static_cast<double>(count);
  double squares = 0.0;
  for (size_t e = 0; e < count; ++e) {
    out[e] = static_cast<float>(out[e] - mean);
    squares += static_cast<double>(out[e]) * out[e];
  }
  if (squares < static_cast<double>(count) * options.min_std * options.min_std || squares <= 0.0)
    return false;
  const float scale = static_cast<float>(1.0 / std::sqrt(squares));
  for (size_t e = 0; e < count; ++e)
    out[e] *= scale;
  return true;
}

float WindowNcc(const NccImage& image, const float* reference_window, double u, double v,
                const EpipolarNccOptions& options) {
  const int mu = options.window, half = mu / 2, ch = image.channels;
  const double fu = std::floor(u), fv = std::floor(v);
  const int x0 = static_cast<int>(fu) - half, y0 = static_cast<int>(fv) - half;
  // Bilinear samples need column x0 + mu and row y0 + mu too.
  if (x0 < 0 || y0 < 0 || x0 + mu >= image.pixels.cols || y0 + mu >= image.pixels.rows) return kNaN;
  const float ax = static_cast<float>(u - fu), ay = static_cast<float>(v - fv);
  const int n = mu * ch;
  float upper[kMaxWindow * 3], lower[kMaxWindow * 3];
  const auto interpolate_row = [&](int y, float* out) {
    const float* p = image.pixels.ptr<float>(y) + x0 * ch;
    for (int e = 0; e < n; ++e)
      out[e] = p[e] + ax * (p[e + ch] - p[e]);
  };
  float* a = upper;
  float* b = lower;
  interpolate_row(y0, a);
  float sum = 0.0f, squares = 0.0f, cross = 0.0f;
  for (int j = 0; j < mu; ++j) {
    interpolate_row(y0 + j + 1, b);
    const float* r = reference_window + j * n;
    for (int e = 0; e < n; ++e) {
      const float w = a[e] + ay * (b[e] - a[e]);
      sum += w;
      squares += w * w;
      cross += r[e] * w;
    }
    std::swap(a, b);
  }
  const float count = static_cast<float>(n * mu);
  const float variance = squares - sum * sum / count;  // times count
  const float min_std = static_cast<float>(options.min_std);
  if (!(variance > 0.0f) || variance < count * min_std * min_std) return kNaN;
  return std::clamp(cross / std::sqrt(variance), -1.0f, 1.0f);
}

EpipolarRay EpipolarRay::Of(const CameraModel& neighbour, const Eigen::Vector3d& centre,
                            const Eigen::Vector3d& direction) {
  EpipolarRay ray;
  ray.a = neighbour.K * (neighbour.R * centre + neighbour.t);
  ray.b = neighbour.K * (neighbour.R * direction);
  return ray;
}

Eigen::Vector2d EpipolarRay::PixelAt(double depth) const {
  const Eigen::Vector3d h = a + depth * b;
  return h.head<2>() / h.z();
}

double EpipolarRay::DepthAt(const Eigen::Vector2d& pixel) const {
  // (a_x + d b_x) = u (a_z + d b_z) and the same in v; the better conditioned one.
  const double du = b.x() - pixel.x() * b.z(), dv = b.y() - pixel.y() * b.z();
  if (std::abs(du) >= std::abs(dv)) return (pixel.x() * a.z() - a.x()) / du;
  return (pixel.y() * a.z() - a.y()) / dv;
}

void ScanEpipolarSegment(const NccImage& neighbour, const float* reference_window,
                         const EpipolarRay& ray, double near, double far,
                         const EpipolarNccOptions& options, std::vector<float>* scores,
                         std::vector<EpipolarMatch>* matches, EpipolarScanCounts* counts) {
  if (!ray.InFront(near) || !ray.InFront(far)) return;
  const Eigen::Vector2d p0 = ray.PixelAt(near), p1 = ray.PixelAt(far);
  const double length = (p1 - p0).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(length / options.step_px)));
  const Eigen::Vector2d delta = (p1 - p0) / steps;
  // Samples -1 .. steps + 1: one beyond each end.
  const int count = steps + 3;
  scores->assign(static_cast<size_t>(count), kNaN);
  const int half = options.window / 2;
  const int cols = neighbour.mask.cols, rows = neighbour.mask.rows;
  for (int s = 0; s < count; ++s) {
    const Eigen::Vector2d p = p0 + (s - 1) * delta;
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    ++counts->samples;
    if (x < 0 || y < 0 || x >= cols || y >= rows || neighbour.mask.at<uint8_t>(y, x) == 0) continue;
    if (options.min_window_in_silhouette > 0.0 &&
        SilhouetteShare(neighbour, x, y, half) < options.min_window_in_silhouette)
      continue;
    const float ncc = WindowNcc(neighbour, reference_window, p.x(), p.y(), options);
    if (std::isnan(ncc)) continue;
    ++counts->scored;
    (*scores)[static_cast<size_t>(s)] = ncc;
  }
  const float threshold = static_cast<float>(options.min_ncc);
  for (int s = 1; s + 1 < count; ++s) {
    const float c = (*scores)[static_cast<size_t>(s)];
    const float l = (*scores)[static_cast<size_t>(s - 1)];
    const float r = (*scores)[static_cast<size_t>(s + 1)];
    // NaN compares false: a maximum needs scored neighbours on both sides.
    if (!(c >= threshold && c > l && c >= r)) continue;
    const double curvature = static_cast<double>(l) - 2.0 * c + r;
    double offset = curvature < 0.0 ? 0.5 * (static_cast<double>(l) - r) / curvature : 0.0;
    offset = std::clamp(offset, -0.5, 0.5);
    const Eigen::Vector2d p = p0 + (s - 1 + offset) * delta;
    ++counts->maxima;
    matches->push_back({ray.DepthAt(p), c});
  }
}

void KeepBestMatches(int count, size_t first, std::vector<EpipolarMatch>* matches) {
  if (count <= 0 || matches->size() <= first + static_cast<size_t>(count)) return;
  const auto begin = matches->begin() + static_cast<std::ptrdiff_t>(first);
  std::sort(begin, matches->end(), [](const EpipolarMatch& x, const EpipolarMatch& y) {
    return x.ncc != y.ncc ? x.ncc > y.ncc : x.depth < y.depth;
  });
  matches->resize(first + static_cast<size_t>(count));
  std::sort(matches->begin() + static_cast<std::ptrdiff_t>(first), matches->end(),
            [](const EpipolarMatch& x, const EpipolarMatch& y) { return x.depth < y.depth; });
}

}  // namespace silnet::aggregator

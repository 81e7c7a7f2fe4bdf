#pragma once
// Masks for silhouette tests: analytic shapes sampled at pixel centres, and random blobs.

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

namespace silnet::testing {

// An ellipse (centre, semi-axes, rotation) sampled exactly at pixel centres.
inline cv::Mat EllipseMask(int width, int height, double cx, double cy, double a, double b,
                           double angle, cv::Mat mask = cv::Mat()) {
  if (mask.empty()) mask = cv::Mat(height, width, CV_8U, cv::Scalar(0));
  const double c = std::cos(angle), s = std::sin(angle);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double dx = x - cx, dy = y - cy;
      const double u = (c * dx + s * dy) / a, v = (-s * dx + c * dy) / b;
      if (u * u + v * v <= 1.0) mask.at<uint8_t>(y, x) = 255;
    }
  }
  return mask;
}

// A random mask of a few ellipses, some possibly crossing the image border.
inline cv::Mat RandomBlobMask(std::mt19937_64& rng, int width, int height, int blobs,
                              bool allow_border) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  cv::Mat mask(height, width, CV_8U, cv::Scalar(0));
  for (int i = 0; i < blobs; ++i) {
    const double margin = allow_border ? -0.1 : 0.25;
    const double cx = width * (margin + (1 - 2 * margin) * u(rng));
    const double cy = height * (margin + (1 - 2 * margin) * u(rng));
    const double a = 3 + 0.2 * width * u(rng), b = 3 + 0.2 * height * u(rng);
    EllipseMask(width, height, cx, cy, a, b, 3.14 * u(rng), mask);
  }
  return mask;
}

}  // namespace silnet::testing

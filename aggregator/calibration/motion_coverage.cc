#include "aggregator/calibration/motion_coverage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {
namespace {

// The hull's extreme along each of `n` directions (max of v . (cos, sin)).
std::vector<double> Extremes(const SilhouetteHull& hull, int n) {
  std::vector<double> out(static_cast<size_t>(n), -1e300);
  for (int d = 0; d < n; ++d) {
    const double angle = 2.0 * std::numbers::pi * d / n;
    const Eigen::Vector2d normal(std::cos(angle), std::sin(angle));
    for (int v = 0; v < hull.size(); ++v)
      out[static_cast<size_t>(d)] =
          std::max(out[static_cast<size_t>(d)], hull.vertex(v).dot(normal));
  }
  return out;
}

}  // namespace

std::string MotionCoverage::Describe() const {
  return fmt::format(
      "swept {:.0f} % of the image, moved in {:.0f} % of the tangent directions, "
      "in {} of {} frames ({} usable)",
      100.0 * image_share, 100.0 * direction_share, moving_frames, frames, usable_frames);
}

MotionCoverage MeasureMotionCoverage(const SilhouetteSequence& sequence,
                                     const MotionCoverageOptions& options) {
  MotionCoverage out;
  out.camera_id = sequence.camera_id;
  out.frames = sequence.frames.size();
  const int side = std::max(sequence.width, sequence.height);
  const double cell = static_cast<double>(std::max(side, 1)) / std::max(options.grid_columns, 1);
  const int columns = std::max(1, static_cast<int>(std::ceil(sequence.width / cell)));
  const int rows = std::max(1, static_cast<int>(std::ceil(sequence.height / cell)));
  out.counts = cv::Mat::zeros(rows, columns, CV_32SC1);
  const int n = std::max(options.directions, 1);
  std::vector<double> sum(static_cast<size_t>(n), 0.0), square(static_cast<size_t>(n), 0.0);
  std::vector<double> previous;
  cv::Mat frame_cells(rows, columns, CV_8UC1);
  for (const SilhouetteFrame& f : sequence.frames) {
    if (sequence.Usable(f.index) == nullptr) continue;
    ++out.usable_frames;
    std::vector<cv::Point> polygon;
    for (int v = 0; v < f.hull.size(); ++v) {
      const Eigen::Vector2d p = f.hull.vertex(v) / cell;
      polygon.emplace_back(static_cast<int>(std::floor(p.x())),
                           static_cast<int>(std::floor(p.y())));
    }
    frame_cells.setTo(0);
    cv::fillConvexPoly(frame_cells, polygon, cv::Scalar(1));
    cv::add(out.counts, frame_cells, out.counts, cv::noArray(), CV_32S);
    const std::vector<double> extremes = Extremes(f.hull, n);
    for (size_t d = 0; d < extremes.size(); ++d) {
      sum[d] += extremes[d];
      square[d] += extremes[d] * extremes[d];
    }
    if (!previous.empty()) {
      double moved = 0.0;
      for (size_t d = 0; d < extremes.size(); ++d)
        moved = std::max(moved, std::abs(extremes[d] - previous[d]));
      if (moved >= options.frame_motion_px) ++out.moving_frames;
    }
    previous = extremes;
  }
  out.image_share =
      static_cast<double>(cv::countNonZero(out.counts)) / static_cast<double>(out.counts.total());
  if (out.usable_frames > 0) {
    const double diagonal = std::hypot(sequence.width, sequence.height);
    int moved = 0;
    for (size_t d = 0; d < sum.size(); ++d) {
      const double mean = sum[d] / static_cast<double>(out.usable_frames);
      const double variance =
          std::max(0.0, square[d] / static_cast<double>(out.usable_frames) - mean * mean);
      moved += std::sqrt(variance) >= options.direction_spread * diagonal ? 1 : 0;
    }
    out.direction_share = static_cast<double>(moved) / n;
  }
  std::vector<std::string> lacking;
  if (out.image_share < options.min_image_share)
    lacking.push_back(
        fmt::format("the silhouettes swept only {:.0f} % of the image (at least "
                    "{:.0f} % needed)",
                    100.0 * out.image_share, 100.0 * options.min_image_share));
  if (out.direction_share < options.min_direction_share)
    lacking.push_back(
        fmt::format("their outline moved in only {:.0f} % of the tangent directions "
                    "(at least {:.0f} % needed)",
                    100.0 * out.direction_share, 100.0 * options.min_direction_share));
  if (out.moving_frames < options.min_moving_frames)
    lacking.push_back(fmt::format("they moved in only {} frames (at least {} needed)",
                                  out.moving_frames, options.min_moving_frames));
  out.sufficient = lacking.empty();
  if (!out.sufficient) {
    std::string joined;
    for (const std::string& l : lacking)
      joined += (joined.empty() ? "" : "; ") + l;
    out.advice = "too little motion: " + joined +
                 ". Walk across the whole capture area, in several directions, and capture "
                 "for longer";
  }
  return out;
}

cv::Mat DrawMotionCoverage(const MotionCoverage& coverage, int width) {
  const cv::Mat& counts = coverage.counts;
  const int cell = std::max(1, width / std::max(counts.cols, 1));
  cv::Mat picture(counts.rows * cell + 40, counts.cols * cell, CV_8UC3, cv::Scalar(255, 255, 255));
  double most = 1.0;
  cv::minMaxLoc(counts, nullptr, &most);
  for (int r = 0; r < counts.rows; ++r) {
    for (int c = 0; c < counts.cols; ++c) {
      const int n = counts.at<int>(r, c);
      const int shade = n == 0 ? 0 : 80 + static_cast<int>(175.0 * n / std::max(most, 1.0));
      cv::rectangle(picture, cv::Rect(c * cell, r * cell, cell, cell),
                    n == 0 ? cv::Scalar(30, 30, 30) : cv::Scalar(shade / 3, shade, shade / 2),
                    cv::FILLED);
    }
  }
  const cv::Scalar ink = coverage.sufficient ? cv::Scalar(0, 110, 0) : cv::Scalar(0, 0, 200);
  cv::putText(picture,
              fmt::format("{}: {:.0f} % image, {:.0f} % directions", coverage.camera_id,
                          100.0 * coverage.image_share, 100.0 * coverage.direction_share),
              {4, counts.rows * cell + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.42, ink, 1, cv::LINE_AA);
  cv::putText(picture,
              fmt::format("moving in {} of {} frames{}", coverage.moving_frames, coverage.frames,
                          coverage.sufficient ? "" : "  TOO LITTLE MOTION"),
              {4, counts.rows * cell + 34}, cv::FONT_HERSHEY_SIMPLEX, 0.42, ink, 1, cv::LINE_AA);
  return picture;
}

}  // namespace silnet::aggregator

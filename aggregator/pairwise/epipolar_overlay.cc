#include "aggregator/pairwise/epipolar_overlay.h"

#include <fmt/format.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {
namespace {

cv::Mat Canvas(const cv::Mat& image, int width, int height) {
  cv::Mat canvas;
  if (image.empty()) {
    canvas = cv::Mat(height, width, CV_8UC3, cv::Scalar(30, 30, 30));
  } else if (image.channels() == 1) {
    cv::cvtColor(image, canvas, cv::COLOR_GRAY2BGR);
    canvas *= 0.5;
  } else {
    canvas = image.clone();
  }
  return canvas;
}

void DrawHull(cv::Mat* canvas, const SilhouetteHull& hull) {
  for (int v = 0; v < hull.size(); ++v) {
    const Eigen::Vector2d& a = hull.vertex(v);
    const Eigen::Vector2d& b = hull.vertex((v + 1) % hull.size());
    cv::line(*canvas, cv::Point2d(a.x(), a.y()), cv::Point2d(b.x(), b.y()),
             hull.edge_clipped(v) ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
  }
}

// Draws the part of a homogeneous line inside the canvas.
void DrawLine(cv::Mat* canvas, const Eigen::Vector3d& line, const cv::Scalar& colour) {
  const double w = canvas->cols, h = canvas->rows;
  std::vector<cv::Point2d> points;
  if (std::abs(line.y()) > 1e-12) {
    for (double x : {0.0, w}) {
      const double y = -(line.z() + line.x() * x) / line.y();
      if (y >= 0 && y <= h) points.emplace_back(x, y);
    }
  }
  if (std::abs(line.x()) > 1e-12) {
    for (double y : {0.0, h}) {
      const double x = -(line.z() + line.y() * y) / line.x();
      if (x >= 0 && x <= w) points.emplace_back(x, y);
    }
  }
  if (points.size() >= 2) cv::line(*canvas, points[0], points[1], colour, 1, cv::LINE_AA);
}

}  // namespace

uint64_t OverlayFrame(const PairwiseResult& pair, const SilhouetteSequence& i,
                      const SilhouetteSequence& j) {
  const std::vector<uint64_t> frames = UsableFrames(i);
  if (frames.empty()) return 0;
  for (size_t step = 0; step < frames.size(); ++step) {
    // Search outwards from the middle.
    const size_t middle = frames.size() / 2;
    const size_t k = step % 2 == 0 ? middle + step / 2 : middle - (step + 1) / 2;
    if (k >= frames.size()) continue;
    TimedMatch matches[2];
    if (MatchAtFrame(pair.model, i, j, frames[k], matches) == 2) return frames[k];
  }
  return frames.front();
}

cv::Mat DrawPairOverlay(const PairwiseResult& pair, const SilhouetteSequence& i,
                        const SilhouetteSequence& j, uint64_t frame_i, const cv::Mat& image_i,
                        const cv::Mat& image_j) {
  cv::Mat left = Canvas(image_i, i.width, i.height);
  cv::Mat right = Canvas(image_j, j.width, j.height);
  // Every inlier frontier point of the sequence.
  for (const TimedMatch& m : pair.inlier_matches) {
    const Eigen::Vector2d xj = m.XjAt(pair.offset);
    cv::circle(left, cv::Point2d(m.x_i.x(), m.x_i.y()), 1, cv::Scalar(255, 160, 0), -1);
    cv::circle(right, cv::Point2d(xj.x(), xj.y()), 1, cv::Scalar(255, 160, 0), -1);
  }
  const SilhouetteFrame* fi = i.Usable(frame_i);
  const SilhouetteFrame *ja = nullptr, *jb = nullptr;
  double fraction = 0.0;
  if (fi != nullptr) DrawHull(&left, fi->hull);
  if (BracketInJ(j, frame_i, pair.offset, &ja, &jb, &fraction))
    DrawHull(&right, fraction < 0.5 ? ja->hull : jb->hull);
  // This frame's outer tangents and frontier points.
  TimedMatch matches[2];
  const int n = MatchAtFrame(pair.model, i, j, frame_i, matches);
  const cv::Scalar colours[2] = {cv::Scalar(0, 220, 255), cv::Scalar(255, 0, 255)};
  for (int m = 0; m < n; ++m) {
    const Eigen::Vector2d xj = matches[m].XjAt(pair.offset);
    DrawLine(&left, pair.model.pencil_i.e.cross(matches[m].x_i.homogeneous()), colours[m]);
    DrawLine(&right, pair.model.LineInJ(matches[m].x_i), colours[m]);
    cv::circle(left, cv::Point2d(matches[m].x_i.x(), matches[m].x_i.y()), 5, colours[m], 2,
               cv::LINE_AA);
    cv::circle(right, cv::Point2d(xj.x(), xj.y()), 5, colours[m], 2, cv::LINE_AA);
  }
  // Epipolar lines of a few points of view i.
  for (int k = 1; k <= 4; ++k) {
    const Eigen::Vector2d x(i.width * 0.5, i.height * k / 5.0);
    const cv::Scalar grey(160, 160, 160);
    cv::drawMarker(left, cv::Point2d(x.x(), x.y()), grey, cv::MARKER_CROSS, 8);
    DrawLine(&right, pair.model.LineInJ(x), grey);
  }
  cv::Mat out;
  cv::hconcat(left, right, out);
  const std::string caption = fmt::format(
      "{} - {}   frame {}   offset {:+.3f}   {} inliers, {:.2f} px   {}", pair.camera_i,
      pair.camera_j, frame_i, pair.offset, pair.inliers, pair.residual_rms, ToString(pair.status));
  cv::putText(out, caption, cv::Point(10, 22), cv::FONT_HERSHEY_SIMPLEX, 0.6,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return out;
}

}  // namespace silnet::aggregator

#include "aggregator/report/plot_canvas.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kBaseFontScale = 0.45;

cv::Point Shifted(cv::Point2d p, cv::Point origin) {
  return {static_cast<int>(std::lround(std::clamp(p.x - origin.x, -1e6, 1e6))),
          static_cast<int>(std::lround(std::clamp(p.y - origin.y, -1e6, 1e6)))};
}

// Pads an empty, inverted or non-finite range.
void Widen(double* lo, double* hi) {
  if (!std::isfinite(*lo) || !std::isfinite(*hi)) {
    *lo = 0.0;
    *hi = 1.0;
  } else if (!(*hi > *lo)) {
    const double centre = 0.5 * (*lo + *hi);
    const double half = centre != 0.0 ? 0.1 * std::abs(centre) : 1.0;
    *lo = centre - half;
    *hi = centre + half;
  }
}

// Text drawn bottom-to-top with its centre at `centre` (dark text on a light background).
void DrawVerticalText(cv::Mat* image, const std::string& text, cv::Point centre, double scale) {
  int baseline = 0;
  const double cv_scale = kBaseFontScale * scale;
  const cv::Size size = cv::getTextSize(text, kFont, cv_scale, 1, &baseline);
  cv::Mat horizontal(size.height + baseline + 2, size.width + 2, CV_8UC3, plot_colour::kBackground);
  cv::putText(horizontal, text, cv::Point(1, size.height + 1), kFont, cv_scale, plot_colour::kText,
              1, cv::LINE_AA);
  cv::Mat vertical;
  cv::rotate(horizontal, vertical, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect target(centre.x - vertical.cols / 2, centre.y - vertical.rows / 2, vertical.cols,
                        vertical.rows);
  const cv::Rect clipped = target & cv::Rect(0, 0, image->cols, image->rows);
  if (clipped.empty()) return;
  cv::Mat destination = (*image)(clipped);
  const cv::Mat source = vertical(clipped - target.tl());
  cv::min(destination, source, destination);
}

}  // namespace

cv::Mat BlankImage(int width, int height) {
  return cv::Mat(std::max(height, 1), std::max(width, 1), CV_8UC3, plot_colour::kBackground);
}

std::vector<double> NiceTicks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo) || target < 1) return {};
  const double raw = (hi - lo) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double r = raw / magnitude;
  const double step = (r < 1.5 ? 1.0 : r < 3.0 ? 2.0 : r < 7.0 ? 5.0 : 10.0) * magnitude;
  std::vector<double> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1.0) {
    ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);
  }
  return ticks;
}

std::string TickLabel(double value) {
  return fmt::format("{:.6g}", value == 0.0 ? 0.0 : value);
}

cv::Scalar TrafficLight(double t) {
  const cv::Scalar green(60, 170, 40), yellow(0, 200, 240), red(40, 40, 210);
  t = std::clamp(std::isfinite(t) ? t : 1.0, 0.0, 1.0);
  if (t < 0.5) return green * (1.0 - 2.0 * t) + yellow * (2.0 * t);
  return yellow * (2.0 - 2.0 * t) + red * (2.0 * t - 1.0);
}

cv::Rect TextBox(const std::string& text, cv::Point2d at, double scale, TextAnchor anchor,
                 bool middle) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, kBaseFontScale * scale, 1, &baseline);
  double x = at.x;
  if (anchor == TextAnchor::kCentre) x -= size.width / 2.0;
  if (anchor == TextAnchor::kRight) x -= size.width;
  const double y = middle ? at.y + size.height / 2.0 : at.y;
  const cv::Point origin(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));
  return {origin.x - 2, origin.y - size.height - 2, size.width + 4, size.height + baseline + 4};
}

cv::Rect DrawText(cv::Mat* image, const std::string& text, cv::Point2d at, double scale,
                  const cv::Scalar& colour, TextAnchor anchor, bool middle,
                  const cv::Scalar* background) {
  const cv::Rect box = TextBox(text, at, scale, anchor, middle);
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, kBaseFontScale * scale, 1, &baseline);
  if (background != nullptr) cv::rectangle(*image, box, *background, cv::FILLED);
  cv::putText(*image, text, cv::Point(box.x + 2, box.y + 2 + size.height), kFont,
              kBaseFontScale * scale, colour, 1, cv::LINE_AA);
  return box;
}

void DrawDashedLine(cv::Mat* image, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour,
                    int thickness, double dash) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  if (!std::isfinite(length) || dash <= 0.0) return;
  const cv::Point2d direction = length > 0.0 ? (b - a) / length : cv::Point2d(0, 0);
  for (double s = 0.0; s < length; s += 2.0 * dash) {
    const double e = std::min(s + dash, length);
    cv::line(*image, a + direction * s, a + direction * e, colour, thickness, cv::LINE_AA);
  }
}

PlotCanvas::PlotCanvas(cv::Mat image, cv::Rect area, double font_scale)
    : image_(std::move(image)),
      area_(area & cv::Rect(0, 0, image_.cols, image_.rows)),
      font_scale_(font_scale) {
  const int left = static_cast<int>(72 * font_scale_), right = 14;
  const int top = static_cast<int>(28 * font_scale_), bottom = static_cast<int>(44 * font_scale_);
  plot_ = cv::Rect(area_.x + left, area_.y + top, std::max(area_.width - left - right, 1),
                   std::max(area_.height - top - bottom, 1));
}

void PlotCanvas::SetRanges(double x_min, double x_max, double y_min, double y_max) {
  Widen(&x_min, &x_max);
  Widen(&y_min, &y_max);
  x_min_ = x_min;
  x_max_ = x_max;
  y_min_ = y_min;
  y_max_ = y_max;
}

void PlotCanvas::MakeEqualAspect() {
  const double per_x = plot_.width / (x_max_ - x_min_);
  const double per_y = plot_.height / (y_max_ - y_min_);
  const double per_unit = std::min(per_x, per_y);
  const double half_x = 0.5 * plot_.width / per_unit, half_y = 0.5 * plot_.height / per_unit;
  const double cx = 0.5 * (x_min_ + x_max_), cy = 0.5 * (y_min_ + y_max_);
  x_min_ = cx - half_x;
  x_max_ = cx + half_x;
  y_min_ = cy - half_y;
  y_max_ = cy + half_y;
}

void PlotCanvas::DrawAxes(const std::string& x_label, const std::string& y_label) {
  const int target_x = std::max(2, plot_.width / 90), target_y = std::max(2, plot_.height / 50);
  const std::vector<double> x_ticks = NiceTicks(x_min_, x_max_, target_x);
  const std::vector<double> y_ticks = NiceTicks(y_min_, y_max_, target_y);
  const int bottom = plot_.y + plot_.height, left = plot_.x;
  for (double x : x_ticks) {
    const int px = static_cast<int>(std::lround(ToPixel(x, 0).x));
    cv::line(image_, {px, plot_.y}, {px, bottom}, plot_colour::kGrid);
    cv::line(image_, {px, bottom}, {px, bottom + 4}, plot_colour::kFrame);
    DrawText(&image_, TickLabel(x), cv::Point2d(px, bottom + 8 + 12 * font_scale_), font_scale_,
             plot_colour::kText, TextAnchor::kCentre);
  }
  for (double y : y_ticks) {
    const int py = static_cast<int>(std::lround(ToPixel(0, y).y));
    cv::line(image_, {left, py}, {left + plot_.width, py}, plot_colour::kGrid);
    cv::line(image_, {left - 4, py}, {left, py}, plot_colour::kFrame);
    DrawText(&image_, TickLabel(y), cv::Point2d(left - 7, py), font_scale_, plot_colour::kText,
             TextAnchor::kRight, true);
  }
  cv::rectangle(image_, plot_, plot_colour::kFrame);
  if (!x_label.empty()) {
    DrawText(&image_, x_label, cv::Point2d(plot_.x + plot_.width / 2.0, area_.y + area_.height - 5),
             font_scale_, plot_colour::kText, TextAnchor::kCentre);
  }
  if (!y_label.empty()) {
    DrawVerticalText(
        &image_, y_label,
        cv::Point(area_.x + static_cast<int>(10 * font_scale_), plot_.y + plot_.height / 2),
        font_scale_);
  }
}

void PlotCanvas::DrawTitle(const std::string& title) {
  DrawText(&image_, title, cv::Point2d(plot_.x + plot_.width / 2.0, plot_.y - 8), font_scale_ * 1.1,
           plot_colour::kText, TextAnchor::kCentre);
}

void PlotCanvas::DrawMessage(const std::string& message) {
  DrawText(&image_, message, cv::Point2d(plot_.x + plot_.width / 2.0, plot_.y + plot_.height / 2.0),
           font_scale_, plot_colour::kFrame, TextAnchor::kCentre, true);
}

cv::Point2d PlotCanvas::ToPixel(double x, double y) const {
  return {plot_.x + (x - x_min_) / (x_max_ - x_min_) * plot_.width,
          plot_.y + plot_.height - (y - y_min_) / (y_max_ - y_min_) * plot_.height};
}

bool PlotCanvas::Contains(double x, double y) const {
  return x >= x_min_ && x <= x_max_ && y >= y_min_ && y <= y_max_;
}

void PlotCanvas::Line(double x0, double y0, double x1, double y1, const cv::Scalar& colour,
                      int thickness) const {
  cv::Mat plot = image_(plot_);
  cv::line(plot, Shifted(ToPixel(x0, y0), plot_.tl()), Shifted(ToPixel(x1, y1), plot_.tl()), colour,
           thickness, cv::LINE_AA);
}

void PlotCanvas::Dot(double x, double y, int radius, const cv::Scalar& colour, bool filled) const {
  if (!Contains(x, y)) return;
  cv::Mat plot = image_(plot_);
  const cv::Point p = Shifted(ToPixel(x, y), plot_.tl());
  if (radius <= 0) {
    plot.at<cv::Vec3b>(std::clamp(p.y, 0, plot.rows - 1), std::clamp(p.x, 0, plot.cols - 1)) =
        cv::Vec3b(static_cast<uchar>(colour[0]), static_cast<uchar>(colour[1]),
                  static_cast<uchar>(colour[2]));
    return;
  }
  cv::circle(plot, p, radius, colour, filled ? cv::FILLED : 1, cv::LINE_AA);
}

void PlotCanvas::Bars(const std::vector<double>& edges, const std::vector<double>& heights,
                      const cv::Scalar& colour) const {
  cv::Mat plot = image_(plot_);
  for (size_t k = 0; k + 1 < edges.size() && k < heights.size(); ++k) {
    if (!(heights[k] > 0.0)) continue;
    const cv::Point a = Shifted(ToPixel(edges[k], 0.0), plot_.tl());
    const cv::Point b = Shifted(ToPixel(edges[k + 1], heights[k]), plot_.tl());
    const cv::Rect bar(cv::Point(std::min(a.x, b.x), std::min(a.y, b.y)),
                       cv::Point(std::max(a.x, b.x) + 1, std::max(a.y, b.y) + 1));
    cv::rectangle(plot, bar, colour, cv::FILLED);
    cv::rectangle(plot, bar, plot_colour::kBackground, 1);
  }
}

void PlotCanvas::Text(double x, double y, const std::string& text, const cv::Scalar& colour,
                      TextAnchor anchor, cv::Point2d pixel_offset) const {
  cv::Mat plot = image_(plot_);
  const cv::Point2d p = ToPixel(x, y) - cv::Point2d(plot_.tl()) + pixel_offset;
  DrawText(&plot, text, p, font_scale_, colour, anchor, true);
}

}  // namespace silnet::aggregator

#include "aggregator/report/offset_graph_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "aggregator/report/plot_canvas.h"
#include "aggregator/report/report_statistics.h"

namespace silnet::aggregator {
namespace {

constexpr double kWorstSigmas = 5.0;  // |residual| / sigma drawn fully red
constexpr int kNodeRadius = 16;

// |residual| / sigma mapped to the colour scale.
cv::Scalar ResidualColour(const SyncEdgeResult& edge) {
  const double sigma = edge.edge.sigma > 0.0 ? edge.edge.sigma : 1.0;
  return TrafficLight(std::abs(edge.residual) / sigma / kWorstSigmas);
}

// "+1.234 ± 0.010", or why the camera has no offset.
std::string OffsetText(const SyncResult& sync, size_t i) {
  if (i < sync.synchronised.size() && !sync.synchronised[i]) return "not synchronised";
  if (i >= sync.offsets.size()) return "no offset";
  const double sigma = i < sync.sigmas.size() ? sync.sigmas[i] : 0.0;
  return fmt::format("{:+.3f} +- {:.3f}", sync.offsets[i], sigma);
}

bool Overlaps(const cv::Rect& box, const std::vector<cv::Rect>& taken) {
  return std::any_of(taken.begin(), taken.end(),
                     [&](const cv::Rect& t) { return !(box & t).empty(); });
}

void DrawLegend(cv::Mat* image, cv::Point corner) {
  const int bar_width = 200, bar_height = 12;
  for (int x = 0; x < bar_width; ++x) {
    cv::line(*image, corner + cv::Point(x, 0), corner + cv::Point(x, bar_height),
             TrafficLight(static_cast<double>(x) / (bar_width - 1)));
  }
  cv::rectangle(*image, cv::Rect(corner, cv::Size(bar_width, bar_height)), plot_colour::kFrame);
  for (int s = 0; s <= static_cast<int>(kWorstSigmas); ++s) {
    const double x = corner.x + bar_width * s / kWorstSigmas;
    DrawText(image, std::to_string(s), cv::Point2d(x, corner.y + bar_height + 14), 0.9,
             plot_colour::kText, TextAnchor::kCentre);
  }
  DrawText(image, "used edge: |residual| / sigma", cv::Point2d(corner.x, corner.y - 6), 0.9,
           plot_colour::kText);
  const cv::Point dashed = corner + cv::Point(bar_width + 40, bar_height / 2);
  DrawDashedLine(image, dashed, dashed + cv::Point(50, 0), plot_colour::kRed, 1);
  DrawText(image, "rejected edge", cv::Point2d(dashed.x + 58, dashed.y), 0.9, plot_colour::kText,
           TextAnchor::kLeft, true);
}

}  // namespace

cv::Mat DrawOffsetGraph(const NetworkCalibration& calibration, int size) {
  cv::Mat image = BlankImage(size, size);
  const SyncResult& sync = calibration.sync;
  const size_t n = calibration.cameras.size();
  const std::string title =
      n == 0
          ? std::string("time offsets (frames)")
          : fmt::format(
                "time offsets (frames), reference {};  rms residual {:.3f} frames "
                "({:.2f} sigma)",
                CameraLabel(calibration, sync.reference), sync.rms_residual, sync.rms_normalised);
  DrawText(&image, title, cv::Point2d(size / 2.0, 28), 1.2, plot_colour::kText,
           TextAnchor::kCentre);
  if (n == 0) {
    DrawText(&image, "no cameras", cv::Point2d(size / 2.0, size / 2.0), 1.2, plot_colour::kFrame,
             TextAnchor::kCentre, true);
    return image;
  }

  const cv::Point2d centre(size / 2.0, size / 2.0 + 5);
  const double radius = n == 1 ? 0.0 : size * 0.33;
  std::vector<cv::Point2d> nodes(n);
  std::vector<cv::Point2d> outward(n);
  for (size_t i = 0; i < n; ++i) {
    const double angle = -std::numbers::pi / 2 + 2.0 * std::numbers::pi * i / n;
    outward[i] = cv::Point2d(std::cos(angle), std::sin(angle));
    nodes[i] = centre + outward[i] * radius;
  }

  std::vector<cv::Rect> taken;  // label boxes and nodes, to keep labels readable
  for (const cv::Point2d& p : nodes) {
    taken.emplace_back(
        cv::Point(static_cast<int>(p.x) - kNodeRadius, static_cast<int>(p.y) - kNodeRadius),
        cv::Size(2 * kNodeRadius, 2 * kNodeRadius));
  }
  // Rejected edges first, so that used ones are drawn on top.
  for (bool used : {false, true}) {
    for (const SyncEdgeResult& e : sync.edges) {
      if (e.used != used || e.edge.i >= n || e.edge.j >= n) continue;
      if (used) {
        cv::line(image, nodes[e.edge.i], nodes[e.edge.j], ResidualColour(e), 2, cv::LINE_AA);
      } else {
        DrawDashedLine(&image, nodes[e.edge.i], nodes[e.edge.j], plot_colour::kRed, 1);
      }
    }
  }
  // Residual labels a third of the way along each edge (midpoints of diameters coincide).
  const cv::Scalar white = plot_colour::kBackground;
  for (const SyncEdgeResult& e : sync.edges) {
    if (e.edge.i >= n || e.edge.j >= n || e.edge.i == e.edge.j) continue;
    const cv::Point2d at = nodes[e.edge.i] + (nodes[e.edge.j] - nodes[e.edge.i]) * 0.35;
    const std::string text = fmt::format("{:+.3f}", e.residual);
    const cv::Rect box = TextBox(text, at, 0.8, TextAnchor::kCentre, true);
    if (Overlaps(box, taken)) continue;
    taken.push_back(box);
    DrawText(&image, text, at, 0.8, e.used ? plot_colour::kText : plot_colour::kRed,
             TextAnchor::kCentre, true, &white);
  }
  for (size_t i = 0; i < n; ++i) {
    const bool synchronised =
        i < sync.synchronised.size() ? sync.synchronised[i] : i < sync.offsets.size();
    const cv::Scalar fill = synchronised ? cv::Scalar(240, 215, 170) : cv::Scalar(215, 215, 215);
    cv::circle(image, nodes[i], kNodeRadius, fill, cv::FILLED, cv::LINE_AA);
    cv::circle(image, nodes[i], kNodeRadius, plot_colour::kFrame, i == sync.reference ? 3 : 1,
               cv::LINE_AA);
    DrawText(&image, std::to_string(i), nodes[i], 0.9, plot_colour::kText, TextAnchor::kCentre,
             true);
    const TextAnchor anchor = outward[i].x > 0.3    ? TextAnchor::kLeft
                              : outward[i].x < -0.3 ? TextAnchor::kRight
                                                    : TextAnchor::kCentre;
    const cv::Point2d label = nodes[i] + outward[i] * (kNodeRadius + 10.0) +
                              cv::Point2d(0, outward[i].y > 0.3    ? 10
                                             : outward[i].y < -0.3 ? -18
                                                                   : -4);
    DrawText(&image, calibration.cameras[i].id, label, 1.0, plot_colour::kText, anchor, true);
    DrawText(&image, OffsetText(sync, i), label + cv::Point2d(0, 17), 0.9,
             synchronised ? plot_colour::kBlue : plot_colour::kRed, anchor, true);
  }
  DrawLegend(&image, cv::Point(20, size - 30));
  return image;
}

}  // namespace silnet::aggregator

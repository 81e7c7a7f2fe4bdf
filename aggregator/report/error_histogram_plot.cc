#include "aggregator/report/error_histogram_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "aggregator/report/plot_canvas.h"
#include "aggregator/report/report_statistics.h"

namespace silnet::aggregator {
namespace {

constexpr int kBins = 20;
constexpr int kMaxColumns = 4;

// The end of the bins: the 99th percentile of all errors rounded up to a nice value.
double BinsEnd(const std::vector<std::vector<double>>& errors) {
  std::vector<double> all;
  for (const std::vector<double>& e : errors)
    all.insert(all.end(), e.begin(), e.end());
  if (all.empty()) return 1.0;
  const size_t k = std::min(all.size() - 1, all.size() * 99 / 100);
  std::nth_element(all.begin(), all.begin() + k, all.end());
  const double p99 = all[k];
  if (!(p99 > 0.0)) return 1.0;
  const std::vector<double> ticks = NiceTicks(0.0, p99, 4);
  const double step = ticks.size() >= 2 ? ticks[1] - ticks[0] : p99;
  return std::ceil(p99 / step - 1e-9) * step;
}

}  // namespace

cv::Mat DrawErrorHistograms(const NetworkCalibration& calibration, int cell_width,
                            int cell_height) {
  const std::vector<std::vector<double>> errors = InlierErrorsPerCamera(calibration);
  std::vector<size_t> cameras;
  for (size_t i = 0; i < calibration.cameras.size(); ++i) {
    if (IsPlaced(calibration, i)) cameras.push_back(i);
  }
  const int cells = std::max<int>(1, static_cast<int>(cameras.size()));
  const int columns = std::min(cells, kMaxColumns);
  const int rows = (cells + columns - 1) / columns;
  cv::Mat image = BlankImage(columns * cell_width, rows * cell_height);
  if (cameras.empty()) {
    PlotCanvas canvas(image, cv::Rect(0, 0, cell_width, cell_height), 0.85);
    canvas.SetRanges(0.0, 1.0, 0.0, 1.0);
    canvas.DrawAxes("reprojection error (px)", "observations");
    canvas.DrawMessage("no placed cameras");
    return image;
  }

  const double end = BinsEnd(errors);
  std::vector<double> edges(kBins + 1);
  for (int b = 0; b <= kBins; ++b)
    edges[b] = end * b / kBins;
  for (size_t k = 0; k < cameras.size(); ++k) {
    const std::vector<double>& e = errors[cameras[k]];
    std::vector<double> counts(kBins, 0.0);
    for (double v : e) {
      const int bin = std::clamp(static_cast<int>(v / end * kBins), 0, kBins - 1);
      counts[bin] += 1.0;
    }
    const int column = static_cast<int>(k) % columns, row = static_cast<int>(k) / columns;
    PlotCanvas canvas(
        image, cv::Rect(column * cell_width, row * cell_height, cell_width, cell_height), 0.85);
    const double highest = *std::max_element(counts.begin(), counts.end());
    canvas.SetRanges(0.0, end, 0.0, std::max(1.0, highest * 1.1));
    canvas.DrawAxes("reprojection error (px)", "observations");
    const std::string id = calibration.cameras[cameras[k]].id;
    if (e.empty()) {
      canvas.DrawTitle(fmt::format("{}: no inlier observations", id));
      canvas.DrawMessage("no observations");
      continue;
    }
    canvas.DrawTitle(
        fmt::format("{}  rms {:.2f}  median {:.2f} px  n={}", id, Rms(e), Median(e), e.size()));
    canvas.Bars(edges, counts, plot_colour::kBlue);
    const double median = Median(e);
    canvas.Line(median, 0.0, median, std::max(1.0, highest * 1.1), plot_colour::kRed);
  }
  return image;
}

}  // namespace silnet::aggregator

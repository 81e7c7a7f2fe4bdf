#include "aggregator/report/report_statistics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace silnet::aggregator {

bool IsPlaced(const NetworkCalibration& calibration, size_t index) {
  return index < calibration.cameras.size() && index < calibration.placement.size() &&
         calibration.placement[index].placed;
}

std::string CameraLabel(const NetworkCalibration& calibration, size_t index) {
  if (index < calibration.cameras.size()) return calibration.cameras[index].id;
  return fmt::format("#{}", index);
}

std::vector<std::vector<double>> InlierErrorsPerCamera(const NetworkCalibration& calibration) {
  std::vector<std::vector<double>> errors(calibration.cameras.size());
  for (const FrontierPoint& point : calibration.points) {
    if (!point.inlier) continue;
    for (const FrontierObservation& view : point.views) {
      if (view.camera < errors.size() && std::isfinite(view.error_px))
        errors[view.camera].push_back(view.error_px);
    }
  }
  return errors;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + middle);
  return 0.5 * (lower + upper);
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values)
    sum += v * v;
  return std::sqrt(sum / values.size());
}

}  // namespace silnet::aggregator

#include "aggregator/calibration/calibration_gates.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

namespace silnet::aggregator {

std::string CalibrationGates::Validate() const {
  if (!(min_focal_factor > 0.0 && max_focal_factor > min_focal_factor))
    return "the focal length gates need 0 < min < max";
  if (!(max_aspect_error >= 0.0 && max_principal_offset > 0.0 && max_abs_k1 > 0.0))
    return "the aspect, principal point and distortion gates must be positive";
  if (!(min_in_front >= 0.0 && min_in_front <= 1.0)) return "the in-front share must lie in [0, 1]";
  if (!(max_rotation_sigma_deg >= 0.0)) return "the rotation uncertainty gate must not be negative";
  return "";
}

std::string GateFailure(const CameraModel& camera, double in_front, const CalibrationGates& gates) {
  const double side = std::max(camera.width, camera.height);
  const double fx = camera.K(0, 0), fy = camera.K(1, 1);
  if (!(fx >= gates.min_focal_factor * side && fx <= gates.max_focal_factor * side)) {
    return fmt::format(
        "focal length {:.1f} px is implausible for a {}x{} image (allowed {:.0f} to "
        "{:.0f} px)",
        fx, camera.width, camera.height, gates.min_focal_factor * side,
        gates.max_focal_factor * side);
  }
  if (!(std::abs(fy / fx - 1.0) <= gates.max_aspect_error))
    return fmt::format("pixel aspect ratio {:.3f} is implausible", fy / fx);
  const double dx = (camera.K(0, 2) - 0.5 * (camera.width - 1)) / camera.width;
  const double dy = (camera.K(1, 2) - 0.5 * (camera.height - 1)) / camera.height;
  if (!(std::abs(dx) <= gates.max_principal_offset && std::abs(dy) <= gates.max_principal_offset)) {
    return fmt::format("principal point ({:.1f}, {:.1f}) is too far from the image centre",
                       camera.K(0, 2), camera.K(1, 2));
  }
  if (!(std::abs(camera.dist[0]) <= gates.max_abs_k1))
    return fmt::format("radial distortion k1 {:.3f} is implausible", camera.dist[0]);
  if (!(in_front >= gates.min_in_front)) {
    return fmt::format("only {:.0f} % of its frontier points lie in front of it", 100.0 * in_front);
  }
  return "";
}

std::string UncertaintyFailure(const CameraUncertainty& uncertainty,
                               const CalibrationGates& gates) {
  if (!uncertainty.estimated || gates.max_rotation_sigma_deg <= 0.0) return "";
  if (uncertainty.rotation_deg <= gates.max_rotation_sigma_deg) return "";
  return fmt::format(
      "its rotation is uncertain by {:.2f} deg (allowed {:.2f}; centre {:.2f} % of the rig, "
      "focal length {:.2f} %): too few or too poorly spread frontier points hold it",
      uncertainty.rotation_deg, gates.max_rotation_sigma_deg, 100.0 * uncertainty.center_rel,
      100.0 * uncertainty.focal_rel);
}

size_t ApplyCalibrationGates(const CalibrationGates& gates, NetworkCalibration* calibration) {
  const size_t n = calibration->cameras.size();
  std::vector<size_t> front(n, 0), total(n, 0);
  for (const FrontierPoint& point : calibration->points) {
    for (const FrontierObservation& o : point.views) {
      if (o.camera >= n) continue;
      const CameraModel& c = calibration->cameras[o.camera];
      ++total[o.camera];
      front[o.camera] += (c.R * point.X + c.t).z() > 0.0 ? 1 : 0;
    }
  }
  size_t rejected = 0;
  for (size_t c = 0; c < n; ++c) {
    CameraPlacement& p = calibration->placement[c];
    if (!p.placed) continue;
    const double in_front =
        total[c] > 0 ? static_cast<double>(front[c]) / static_cast<double>(total[c]) : 0.0;
    std::string why = GateFailure(calibration->cameras[c], in_front, gates);
    if (why.empty()) why = UncertaintyFailure(p.uncertainty, gates);
    if (why.empty()) continue;
    spdlog::warn("{} fails a sanity check and is not calibrated: {}", calibration->cameras[c].id,
                 why);
    p.placed = false;
    p.reason = "fails a sanity check: " + why;
    ++rejected;
  }
  return rejected;
}

}  // namespace silnet::aggregator

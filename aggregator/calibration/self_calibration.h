#pragma once
// Linear self-calibration (thesis 3.2.5, ref. 108: Pollefeys et al.): the absolute dual
// quadric Omega* of a projective reconstruction from the constraints its images
// omega*_i = P_i Omega* P_i^T = K_i K_i^T satisfy for cameras with zero skew, principal point
// near the image centre and focal length of the order of the image size (in normalised
// coordinates), weighted by how loosely each holds and re-weighted by the current scale;
// then the rank-3 positive semi-definite Omega* closest to the solution, and the
// rectifying homography H (Omega* = H diag(1,1,1,0) H^T) that makes P_i H metric.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "shared/geometry/camera_model.h"

namespace silnet::aggregator {

// The upgrade of a projective reconstruction to a metric one.
struct MetricUpgrade {
  Eigen::Matrix4d H = Eigen::Matrix4d::Identity();  // P_metric = P H, X_metric = H^-1 X
  Eigen::Matrix4d omega = Eigen::Matrix4d::Zero();  // the absolute dual quadric found
};

// Self-calibrates the `present` cameras (normalised coordinates, ImageNormalization); needs at
// least 3. nullopt with a reason if the quadric is not positive semi-definite of rank 3 (too
// few cameras or a critical configuration).
std::optional<MetricUpgrade> SelfCalibrateLinear(const std::vector<Matrix34d>& cameras,
                                                 const std::vector<bool>& present,
                                                 std::string* why);

}  // namespace silnet::aggregator

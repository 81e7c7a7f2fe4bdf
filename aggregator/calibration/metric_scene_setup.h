#pragma once
// Turning reconstructions into metric scenes ready for Euclidean bundle adjustment: the
// projective cameras through the self-calibration's upgrade (decomposed into K, R, t, with
// the reconstruction mirrored if the points came out behind the cameras), and the choice of
// world frame (the reconstruction fixes it only up to a similarity).

#include <optional>
#include <string>
#include <vector>

#include "aggregator/calibration/euclidean_bundle_adjustment.h"
#include "aggregator/calibration/projective_bundle_adjustment.h"
#include "aggregator/calibration/self_calibration.h"

namespace silnet::aggregator {

// The metric scene of a projective reconstruction upgraded by `upgrade`; `templates` gives
// each camera's id, image size and clock, which the result keeps. Skew is dropped (the
// Euclidean model has none). nullopt with a reason if a camera does not decompose or the
// points are not in front of most cameras however the scene is mirrored.
std::optional<MetricScene> UpgradeToMetric(const ProjectiveScene& scene,
                                           const MetricUpgrade& upgrade,
                                           const std::vector<CameraModel>& templates,
                                           std::string* why);

// Moves the scene into silnet's world frame for a camera rig: origin at the centroid of the
// camera centres, Z along the cameras' mean "up" (image -y), X towards the first camera,
// scaled so the mean distance of the centres from the origin is `rig_radius`.
void NormalizeGauge(MetricScene* scene, double rig_radius);

// The fraction of track observations in front of their camera.
double FractionInFront(const MetricScene& scene);

}  // namespace silnet::aggregator

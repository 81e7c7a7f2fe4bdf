#include "aggregator/calibration/metric_scene_setup.h"

#include <Eigen/Geometry>

#include "aggregator/calibration/projective_geometry.h"

namespace silnet::aggregator {

double FractionInFront(const MetricScene& scene) {
  size_t in_front = 0, total = 0;
  for (size_t k = 0; k < scene.tracks.size(); ++k) {
    const TwoViewTrack& t = scene.tracks[k];
    for (size_t camera : {t.camera_a, t.camera_b}) {
      const CameraModel& c = scene.cameras[camera];
      in_front += (c.R * scene.points[k] + c.t).z() > 0.0 ? 1 : 0;
      ++total;
    }
  }
  return total == 0 ? 0.0 : static_cast<double>(in_front) / static_cast<double>(total);
}

std::optional<MetricScene> UpgradeToMetric(const ProjectiveScene& scene,
                                           const MetricUpgrade& upgrade,
                                           const std::vector<CameraModel>& templates,
                                           std::string* why) {
  MetricScene out;
  out.present = scene.present;
  out.cameras = templates;
  out.tracks = scene.tracks;
  for (size_t c = 0; c < scene.cameras.size(); ++c) {
    if (!scene.present[c]) continue;
    const Matrix34d pixels = scene.normalization[c].inverse() * scene.cameras[c] * upgrade.H;
    CameraModel& camera = out.cameras[c];
    Eigen::Matrix3d k;
    if (!DecomposeProjection(pixels, &k, &camera.R, &camera.t)) {
      if (why) *why = "camera " + camera.id + " is at infinity after the metric upgrade";
      return std::nullopt;
    }
    k(0, 1) = 0.0;
    camera.K = k;
    camera.dist.setZero();
  }
  out.Triangulate();
  if (FractionInFront(out) < 0.5) {
    // The mirror image: every camera's translation and every point negated.
    for (size_t c = 0; c < out.cameras.size(); ++c)
      out.cameras[c].t = -out.cameras[c].t;
    for (Eigen::Vector3d& x : out.points)
      x = -x;
  }
  const double in_front = FractionInFront(out);
  if (in_front < 0.9) {
    if (why) {
      *why = "after the metric upgrade only " + std::to_string(static_cast<int>(100 * in_front)) +
             " % of the frontier points lie in front of their cameras";
    }
    return std::nullopt;
  }
  return out;
}

void NormalizeGauge(MetricScene* scene, double rig_radius) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  size_t n = 0;
  size_t first = scene->cameras.size();
  for (size_t c = 0; c < scene->cameras.size(); ++c) {
    if (!scene->present[c]) continue;
    centroid += scene->cameras[c].Center();
    up += -scene->cameras[c].R.row(1).transpose();
    first = std::min(first, c);
    ++n;
  }
  if (n < 2) return;
  centroid /= static_cast<double>(n);
  double mean_distance = 0.0;
  for (size_t c = 0; c < scene->cameras.size(); ++c) {
    if (scene->present[c]) mean_distance += (scene->cameras[c].Center() - centroid).norm();
  }
  mean_distance /= static_cast<double>(n);
  if (!(mean_distance > 0.0) || up.norm() < 1e-9) return;
  const Eigen::Vector3d z = up.normalized();
  Eigen::Vector3d x = scene->cameras[first].Center() - centroid;
  x -= x.dot(z) * z;
  if (x.norm() < 1e-9 * mean_distance) x = z.unitOrthogonal();
  x.normalize();
  Eigen::Matrix3d q;  // rows: the new axes in old coordinates
  q.row(0) = x.transpose();
  q.row(1) = z.cross(x).transpose();
  q.row(2) = z.transpose();
  const double s = rig_radius / mean_distance;
  for (size_t c = 0; c < scene->cameras.size(); ++c) {
    if (!scene->present[c]) continue;
    CameraModel& camera = scene->cameras[c];
    camera.t = s * (camera.R * centroid + camera.t);
    camera.R = camera.R * q.transpose();
  }
  for (Eigen::Vector3d& p : scene->points)
    p = s * q * (p - centroid);
}

}  // namespace silnet::aggregator

#include "tests/sim/reference_raster.h"

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

namespace silnet::sim::testing {
namespace {

// Distance between the ray {s d : s >= 0} and the segment a-b.
double RaySegmentDistance(const Eigen::Vector3d& d, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b) {
  // Minimise |s d - (a + u (b - a))| over s >= 0, u in [0, 1] by checking the interior
  // stationary point and the boundary cases.
  const Eigen::Vector3d e = b - a;
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](double s, double u) {
    s = std::max(0.0, s);
    u = std::clamp(u, 0.0, 1.0);
    best = std::min(best, (s * d - (a + u * e)).norm());
  };
  const double dd = d.dot(d), de = d.dot(e), ee = e.dot(e), da = d.dot(a), ea = e.dot(a);
  const double det = dd * ee - de * de;
  if (std::abs(det) > 1e-15) {
    const double s = (da * ee - de * ea) / det;
    const double u = (de * da - dd * ea) / det;
    if (s >= 0.0 && u >= 0.0 && u <= 1.0) consider(s, u);
  }
  for (double u : {0.0, 1.0})
    consider(d.dot(a + u * e) / dd, u);  // segment ends
  if (ee > 0) consider(0.0, -ea / ee);   // ray origin
  return best;
}

}  // namespace

cv::Mat ReferenceMask(const CameraModel& camera, const std::vector<Primitive>& world) {
  cv::Mat K, dist;
  cv::eigen2cv(camera.K, K);
  cv::eigen2cv(Eigen::Matrix<double, 1, 5>(camera.dist.transpose()), dist);
  std::vector<cv::Point2d> pixels, normalized;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x)
      pixels.emplace_back(x, y);
  cv::undistortPoints(
      pixels, normalized, K, dist, cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
  // Image conics of the ellipsoids in normalised coordinates, sign fixed by the centre.
  struct Conic {
    Eigen::Matrix3d c;
    double inside_sign;
  };
  std::vector<Conic> conics;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
  std::vector<double> radii;
  for (const Primitive& p : world) {
    const Primitive q = p.Transformed(camera.R, camera.t);
    if (q.kind == PrimitiveKind::kCapsule) {
      segments.emplace_back(q.a, q.b);
      radii.push_back(q.radius);
      continue;
    }
    const Eigen::Matrix3d A =
        q.axes * q.radii.cwiseInverse().cwiseAbs2().asDiagonal() * q.axes.transpose();
    Eigen::Matrix4d Q = Eigen::Matrix4d::Zero();
    Q.topLeftCorner<3, 3>() = A;
    Q.topRightCorner<3, 1>() = -A * q.center;
    Q.bottomLeftCorner<1, 3>() = (-A * q.center).transpose();
    Q(3, 3) = q.center.dot(A * q.center) - 1.0;
    const Eigen::Matrix3d dual = Q.inverse().topLeftCorner<3, 3>();
    const Eigen::Matrix3d c = dual.inverse();
    const Eigen::Vector3d centre = q.center / q.center.z();
    conics.push_back({c, centre.dot(c * centre) < 0 ? -1.0 : 1.0});
  }
  cv::Mat mask(camera.height, camera.width, CV_8U, cv::Scalar(0));
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const cv::Point2d& n = normalized[static_cast<size_t>(y * camera.width + x)];
      const Eigen::Vector3d ray(n.x, n.y, 1.0);
      bool inside = false;
      for (const Conic& k : conics) {
        if (k.inside_sign * ray.dot(k.c * ray) > 0) {
          inside = true;
          break;
        }
      }
      for (size_t s = 0; !inside && s < segments.size(); ++s) {
        inside = RaySegmentDistance(ray, segments[s].first, segments[s].second) <= radii[s];
      }
      if (inside) mask.at<uint8_t>(y, x) = 255;
    }
  }
  return mask;
}

double MaskIoU(const cv::Mat& a, const cv::Mat& b) {
  const double intersection = cv::countNonZero(a & b);
  const double uni = cv::countNonZero(a | b);
  return uni == 0 ? 1.0 : intersection / uni;
}

}  // namespace silnet::sim::testing

#include "shared/geometry/epipolar.h"

#include <Eigen/Dense>
#include <cmath>

namespace silnet {
namespace {

Eigen::Vector3d NullVector(const Eigen::Matrix3d& m) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullV);
  return svd.matrixV().col(2);
}

}  // namespace

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

Eigen::Matrix3d FundamentalFromCameras(const CameraModel& camera_i, const CameraModel& camera_j) {
  const Eigen::Matrix3d r = camera_j.R * camera_i.R.transpose();  // j_from_i
  const Eigen::Vector3d t = camera_j.t - r * camera_i.t;
  const Eigen::Matrix3d essential = Skew(t) * r;
  const Eigen::Matrix3d f = camera_j.K.inverse().transpose() * essential * camera_i.K.inverse();
  return NormalizeFundamental(f);
}

Eigen::Matrix3d NormalizeFundamental(const Eigen::Matrix3d& f) {
  Eigen::Matrix3d n = f / f.norm();
  Eigen::Index row = 0, col = 0;
  n.cwiseAbs().maxCoeff(&row, &col);
  if (n(row, col) < 0) n = -n;
  return n;
}

Eigen::Vector3d EpipoleInFirstView(const Eigen::Matrix3d& f) {
  return NullVector(f);
}

Eigen::Vector3d EpipoleInSecondView(const Eigen::Matrix3d& f) {
  return NullVector(f.transpose());
}

double PointLineDistance(const Eigen::Vector3d& line, const Eigen::Vector2d& x) {
  return std::abs(line.dot(x.homogeneous())) / line.head<2>().norm();
}

double SymmetricEpipolarDistance(const Eigen::Matrix3d& f, const Eigen::Vector2d& x_i,
                                 const Eigen::Vector2d& x_j) {
  const double d_j = PointLineDistance(f * x_i.homogeneous(), x_j);
  const double d_i = PointLineDistance(f.transpose() * x_j.homogeneous(), x_i);
  return std::sqrt(0.5 * (d_i * d_i + d_j * d_j));
}

PairTiming PairTimingFromCameras(const CameraModel& camera_i, const CameraModel& camera_j) {
  // (k + o_i) / f_i = (k_j + o_j) / f_j  =>  k_j = (f_j / f_i) k + (f_j / f_i) o_i - o_j.
  PairTiming timing;
  timing.rate = camera_j.fps / camera_i.fps;
  timing.offset = timing.rate * camera_i.time_offset - camera_j.time_offset;
  return timing;
}

}  // namespace silnet

#include "aggregator/calibration/ground_truth_comparison.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>

#include "shared/util/check.h"
#include "shared/util/statistics.h"

namespace silnet::aggregator {
namespace {

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

using CameraPairs = std::vector<std::pair<const CameraModel*, const CameraModel*>>;

// The cameras of `estimated` (those `placed`; all if it is null) with their namesakes in
// `truth`; at least 3, else InputError.
CameraPairs MatchCameras(const std::vector<CameraModel>& estimated, const std::vector<bool>* placed,
                         const std::vector<CameraModel>& truth) {
  CameraPairs matched;
  for (size_t c = 0; c < estimated.size(); ++c) {
    if (placed != nullptr && (c >= placed->size() || !(*placed)[c])) continue;
    const auto t = std::find_if(truth.begin(), truth.end(),
                                [&](const CameraModel& m) { return m.id == estimated[c].id; });
    if (t != truth.end()) matched.emplace_back(&estimated[c], &*t);
  }
  if (matched.size() < 3)
    throw InputError("comparing with ground truth needs at least 3 calibrated cameras it knows");
  return matched;
}

// The centres of the matched cameras, estimated (src) and true (dst).
std::pair<Eigen::Matrix3Xd, Eigen::Matrix3Xd> Centres(const CameraPairs& matched) {
  const auto n = static_cast<Eigen::Index>(matched.size());
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    src.col(k) = matched[static_cast<size_t>(k)].first->Center();
    dst.col(k) = matched[static_cast<size_t>(k)].second->Center();
  }
  return {src, dst};
}

// `cameras` moved into the frame X' = similarity * X (uniform scale).
std::vector<CameraModel> Moved(std::vector<CameraModel> cameras,
                               const Eigen::Matrix4d& similarity) {
  const Eigen::Matrix3d sq = similarity.topLeftCorner<3, 3>();
  const double scale = std::cbrt(sq.determinant());
  const Eigen::Matrix3d q = sq / scale;
  const Eigen::Vector3d shift = similarity.topRightCorner<3, 1>();
  // X_true = scale q X + shift; x_cam = R X + t becomes, scaled by `scale`,
  // x_cam = R q^T X_true + scale t - R q^T shift.
  for (CameraModel& c : cameras) {
    const Eigen::Matrix3d rotation = c.R * q.transpose();
    c.t = scale * c.t - rotation * shift;
    c.R = rotation;
  }
  return cameras;
}

// Linear triangulation of one point from its undistorted pixels in two or more cameras.
Eigen::Vector3d TriangulateViews(const std::vector<const CameraModel*>& cameras,
                                 const std::vector<Eigen::Vector2d>& pixels) {
  Eigen::MatrixXd a(2 * cameras.size(), 4);
  for (size_t k = 0; k < cameras.size(); ++k) {
    const Matrix34d p = cameras[k]->ProjectionMatrix();
    const auto row = static_cast<Eigen::Index>(2 * k);
    a.row(row) = pixels[k].x() * p.row(2) - p.row(0);
    a.row(row + 1) = pixels[k].y() * p.row(2) - p.row(1);
  }
  const Eigen::Vector4d x =
      Eigen::JacobiSVD<Eigen::MatrixXd>(a, Eigen::ComputeFullV).matrixV().col(3);
  return x.hnormalized();
}

}  // namespace

std::vector<CameraModel> AlignedAtSubject(const std::vector<CameraModel>& estimated,
                                          const std::vector<CameraModel>& truth,
                                          const std::vector<Eigen::Vector3d>& subject) {
  const CameraPairs matched = MatchCameras(estimated, nullptr, truth);
  const size_t step = std::max<size_t>(1, subject.size() / 5000);
  std::vector<Eigen::Vector3d> from, to;
  for (size_t k = 0; k < subject.size(); k += step) {
    std::vector<const CameraModel*> seen_by;
    std::vector<Eigen::Vector2d> pixels;
    for (const auto& [est, tru] : matched) {
      const auto pixel = tru->Project(subject[k]);
      if (!pixel || !tru->InImage(*pixel)) continue;
      seen_by.push_back(est);
      pixels.push_back(est->UndistortPixel(*pixel));
    }
    if (seen_by.size() < 2) continue;
    from.push_back(TriangulateViews(seen_by, pixels));
    to.push_back(subject[k]);
  }
  if (from.size() < 100)
    throw InputError(fmt::format("only {} subject points are seen by two cameras", from.size()));
  Eigen::Matrix3Xd src(3, static_cast<Eigen::Index>(from.size()));
  Eigen::Matrix3Xd dst(3, static_cast<Eigen::Index>(to.size()));
  for (size_t k = 0; k < from.size(); ++k) {
    src.col(static_cast<Eigen::Index>(k)) = from[k];
    dst.col(static_cast<Eigen::Index>(k)) = to[k];
  }
  return Moved(estimated, Eigen::umeyama(src, dst, true));
}

CalibrationErrors CompareWithGroundTruth(const std::vector<CameraModel>& estimated,
                                         const std::vector<bool>& placed,
                                         const std::vector<CameraModel>& truth) {
  const CameraPairs matched = MatchCameras(estimated, &placed, truth);
  const auto n = static_cast<Eigen::Index>(matched.size());
  const auto [src, dst] = Centres(matched);
  const Eigen::Matrix4d similarity = Eigen::umeyama(src, dst, true);
  const Eigen::Matrix3d sq = similarity.topLeftCorner<3, 3>();
  const double scale = std::cbrt(sq.determinant());
  const Eigen::Matrix3d q = sq / scale;

  CalibrationErrors e;
  for (Eigen::Index a = 0; a < n; ++a) {
    for (Eigen::Index b = a + 1; b < n; ++b)
      e.rig_diameter = std::max(e.rig_diameter, (dst.col(a) - dst.col(b)).norm());
  }
  double offset_shift = 0.0;
  for (const auto& [est, tru] : matched)
    offset_shift += est->time_offset - tru->time_offset;
  offset_shift /= static_cast<double>(matched.size());

  std::vector<double> focal, rotation, centre, offset, k1;
  for (Eigen::Index k = 0; k < n; ++k) {
    const CameraModel& est = *matched[static_cast<size_t>(k)].first;
    const CameraModel& tru = *matched[static_cast<size_t>(k)].second;
    CameraError c;
    c.id = est.id;
    c.focal_rel =
        std::abs(0.5 * (est.K(0, 0) + est.K(1, 1)) / (0.5 * (tru.K(0, 0) + tru.K(1, 1))) - 1.0);
    const Eigen::Matrix3d aligned = est.R * q.transpose();
    c.rotation_deg = Eigen::AngleAxisd(aligned * tru.R.transpose()).angle() * 180.0 / EIGEN_PI;
    const Eigen::Vector3d centre_aligned = (similarity * src.col(k).homogeneous()).head<3>();
    c.center_rel = (centre_aligned - dst.col(k)).norm() / std::max(e.rig_diameter, 1e-12);
    c.principal_px = (est.K.block<2, 1>(0, 2) - tru.K.block<2, 1>(0, 2)).norm();
    c.k1_error = std::abs(est.dist[0] - tru.dist[0]);
    c.offset_frames = std::abs(est.time_offset - tru.time_offset - offset_shift);
    focal.push_back(c.focal_rel);
    rotation.push_back(c.rotation_deg);
    centre.push_back(c.center_rel);
    offset.push_back(c.offset_frames);
    k1.push_back(c.k1_error);
    e.cameras.push_back(c);
  }
  e.median_focal_rel = UpperMedian(focal);
  e.max_focal_rel = Max(focal);
  e.median_rotation_deg = UpperMedian(rotation);
  e.max_rotation_deg = Max(rotation);
  e.median_center_rel = UpperMedian(centre);
  e.max_center_rel = Max(centre);
  e.median_offset_frames = UpperMedian(offset);
  e.max_offset_frames = Max(offset);
  e.median_k1_error = UpperMedian(k1);
  return e;
}

}  // namespace silnet::aggregator

#include "aggregator/hulls/viewing_cone_bounds.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace silnet::aggregator {
namespace {

// A half-space {X : normal . X + offset >= 0} with a unit normal.
struct HalfSpace {
  Eigen::Vector3d normal;
  double offset = 0.0;
};

HalfSpace MakeHalfSpace(const Eigen::Vector4d& row) {
  const double n = row.head<3>().norm();
  return {row.head<3>() / n, row[3] / n};
}

// Bounding rectangle of the silhouette in undistorted pixels, covering every pixel's area.
Eigen::AlignedBox2d UndistortedSilhouetteRect(const CameraModel& camera, const cv::Rect& rect) {
  const double x0 = rect.x - 0.5, x1 = rect.x + rect.width - 0.5;
  const double y0 = rect.y - 0.5, y1 = rect.y + rect.height - 0.5;
  Eigen::AlignedBox2d box;
  if (!camera.HasDistortion()) {
    box.extend(Eigen::Vector2d(x0, y0));
    box.extend(Eigen::Vector2d(x1, y1));
    return box;
  }
  // Distortion bends the rectangle's sides: walk its outline densely.
  constexpr int kSteps = 64;
  for (int s = 0; s <= kSteps; ++s) {
    const double f = static_cast<double>(s) / kSteps;
    const double x = x0 + f * (x1 - x0), y = y0 + f * (y1 - y0);
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(x, y0), Eigen::Vector2d(x, y1),
                                     Eigen::Vector2d(x0, y), Eigen::Vector2d(x1, y)}) {
      box.extend(camera.UndistortPixel(p));
    }
  }
  // A little slack for the sampling of the bent sides.
  box.min().array() -= 0.5;
  box.max().array() += 0.5;
  return box;
}

// False only if no point X on the line where planes a and b meet passes every half-space with
// the slack `tolerance` * (1 + |X|) (so no vertex there does): the line clipped by each
// half-space on its two halves from a point X0 on it, with ten times the slack.
bool LineCanHoldVertex(const std::vector<HalfSpace>& planes, size_t a, size_t b, double tolerance) {
  const Eigen::Vector3d d = planes[a].normal.cross(planes[b].normal);
  const double d_norm = d.norm();
  if (d_norm < 1e-12) return true;
  // The line's point nearest the origin (n_a . X0 = -o_a, n_b . X0 = -o_b, d . X0 = 0).
  const Eigen::Vector3d x0 = -(planes[a].offset * planes[b].normal.cross(d) +
                               planes[b].offset * d.cross(planes[a].normal)) /
                             (d_norm * d_norm);
  const double slack = 10 * tolerance;
  const double x0_slack = slack * (1 + x0.norm());
  // On each half t >= 0 and t <= 0 (X = X0 + t d, s the half's sign), every half-space asks
  // (s n . d + slack |d|) |t| >= -(n . X0 + o) - slack (1 + |X0|): implied by its vertex test,
  // as |X| <= |X0| + |t| |d|.
  for (const double sign : {1.0, -1.0}) {
    double lo = 0, hi = std::numeric_limits<double>::infinity();
    for (const HalfSpace& h : planes) {
      const double rate = sign * h.normal.dot(d) + slack * d_norm;
      const double need = -(h.normal.dot(x0) + h.offset) - x0_slack;
      if (rate > 0) {
        lo = std::max(lo, need / rate);
      } else if (rate < 0) {
        hi = std::min(hi, need / rate);
      } else if (need > 0) {
        hi = -1;
      }
      if (lo > hi) break;
    }
    if (lo <= hi) return true;
  }
  return false;
}

}  // namespace

std::string MaskShapeProblem(const CameraModel& camera, const cv::Mat& mask) {
  if (mask.type() == CV_8UC1 && mask.cols == camera.width && mask.rows == camera.height) return {};
  return "mask of " + camera.id + " is not a CV_8UC1 image of the camera's size";
}

ViewingConeBounds ComputeViewingConeBounds(const std::vector<CameraModel>& cameras,
                                           const std::vector<cv::Mat>& masks) {
  ViewingConeBounds result;
  if (cameras.size() != masks.size() || cameras.empty()) {
    result.reason = "need one mask per camera";
    return result;
  }
  std::vector<cv::Rect> rects;
  for (size_t c = 0; c < cameras.size(); ++c) {
    result.reason = MaskShapeProblem(cameras[c], masks[c]);
    if (!result.reason.empty()) return result;
    rects.push_back(cv::boundingRect(masks[c]));  // of the non-zero pixels
  }
  return ComputeViewingConeBounds(cameras, rects);
}

ViewingConeBounds ComputeViewingConeBounds(const std::vector<CameraModel>& cameras,
                                           const std::vector<cv::Rect>& rects) {
  ViewingConeBounds result;
  if (cameras.size() != rects.size() || cameras.empty()) {
    result.reason = "need one silhouette rectangle per camera";
    return result;
  }
  std::vector<HalfSpace> planes;
  for (size_t c = 0; c < cameras.size(); ++c) {
    const CameraModel& camera = cameras[c];
    const cv::Rect& rect = rects[c];
    if (rect.empty()) {
      result.reason = "silhouette of " + camera.id + " is empty";
      return result;
    }
    const Eigen::AlignedBox2d r = UndistortedSilhouetteRect(camera, rect);
    const Matrix34d P = camera.ProjectionMatrix();
    const Eigen::Vector4d row_u = P.row(0).transpose(), row_v = P.row(1).transpose();
    const Eigen::Vector4d row_w = P.row(2).transpose();
    planes.push_back(MakeHalfSpace(row_w));  // in front of the camera
    if (rect.x > 0) planes.push_back(MakeHalfSpace(row_u - r.min().x() * row_w));
    if (rect.x + rect.width < camera.width) {
      planes.push_back(MakeHalfSpace(r.max().x() * row_w - row_u));
    }
    if (rect.y > 0) planes.push_back(MakeHalfSpace(row_v - r.min().y() * row_w));
    if (rect.y + rect.height < camera.height) {
      planes.push_back(MakeHalfSpace(r.max().y() * row_w - row_v));
    }
  }
  // Bounded iff the recession cone {d : n . d >= 0 for all planes} is {0}. The normals must
  // span R^3, and no edge direction (cross product of two normals) may lie in the cone.
  Eigen::MatrixXd normals(3, static_cast<Eigen::Index>(planes.size()));
  for (size_t p = 0; p < planes.size(); ++p)
    normals.col(static_cast<Eigen::Index>(p)) = planes[p].normal;
  if (Eigen::FullPivLU<Eigen::MatrixXd>(normals).rank() < 3) {
    result.reason = "viewing cones do not bound a finite region";
    return result;
  }
  constexpr double kTolerance = 1e-9;
  for (size_t a = 0; a < planes.size(); ++a) {
    for (size_t b = a + 1; b < planes.size(); ++b) {
      const Eigen::Vector3d d = planes[a].normal.cross(planes[b].normal);
      if (d.norm() < 1e-12) continue;
      for (const Eigen::Vector3d& dir : {d.normalized(), Eigen::Vector3d(-d.normalized())}) {
        const bool in_cone = std::all_of(planes.begin(), planes.end(), [&](const HalfSpace& h) {
          return h.normal.dot(dir) >= -kTolerance;
        });
        if (in_cone) {
          result.reason = "viewing cones do not bound a finite region";
          return result;
        }
      }
    }
  }
  // Bounded: the box of the polyhedron's vertices (intersections of three planes), found on
  // the lines of the plane pairs that can hold one.
  WorldBox box;
  for (size_t a = 0; a < planes.size(); ++a) {
    for (size_t b = a + 1; b < planes.size(); ++b) {
      if (!LineCanHoldVertex(planes, a, b, kTolerance)) continue;
      for (size_t c = b + 1; c < planes.size(); ++c) {
        // Cramer's rule: X = -(o_a (n_b x n_c) + o_b (n_c x n_a) + o_c (n_a x n_b)) / det.
        const Eigen::Vector3d bc = planes[b].normal.cross(planes[c].normal);
        const double det = planes[a].normal.dot(bc);
        if (std::abs(det) < 1e-12) continue;
        const Eigen::Vector3d X =
            -(planes[a].offset * bc + planes[b].offset * planes[c].normal.cross(planes[a].normal) +
              planes[c].offset * planes[a].normal.cross(planes[b].normal)) /
            det;
        const double scale = 1.0 + X.norm();
        const bool inside = std::all_of(planes.begin(), planes.end(), [&](const HalfSpace& h) {
          return h.normal.dot(X) + h.offset >= -kTolerance * scale;
        });
        if (inside) box.extend(X);
      }
    }
  }
  if (box.isEmpty()) {
    result.reason = "viewing cones do not intersect";
    return result;
  }
  result.success = true;
  result.box = box;
  return result;
}

}  // namespace silnet::aggregator

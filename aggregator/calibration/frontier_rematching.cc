#include "aggregator/calibration/frontier_rematching.h"

#include <cmath>
#include <numbers>
#include <optional>

#include "aggregator/pairwise/epipolar_model.h"
#include "aggregator/pairwise/frame_pairing.h"
#include "shared/geometry/epipolar.h"
#include "shared/silhouette/melkman_hull.h"

namespace silnet::aggregator {
namespace {

SilhouetteHull UndistortHull(const SilhouetteHull& hull, const CameraModel& camera) {
  std::vector<Eigen::Vector2d> moved;
  moved.reserve(static_cast<size_t>(hull.size()) + 1);
  for (const Eigen::Vector2d& v : hull.vertices())
    moved.push_back(camera.UndistortPixel(v));
  moved.push_back(moved.front());
  std::vector<Eigen::Vector2d> vertices = MelkmanHull(moved);
  if (vertices.size() < 3) return {};
  std::vector<bool> clipped(vertices.size(), false);
  const auto original = [&](const Eigen::Vector2d& v) {
    for (int i = 0; i < hull.size(); ++i) {
      if (moved[static_cast<size_t>(i)] == v) return i;
    }
    return -1;
  };
  for (size_t e = 0; e < vertices.size(); ++e) {
    const int a = original(vertices[e]);
    const int b = original(vertices[(e + 1) % vertices.size()]);
    clipped[e] =
        a >= 0 && b >= 0 && hull.vertex_on_clipped_edge(a) && hull.vertex_on_clipped_edge(b);
  }
  return SilhouetteHull(std::move(vertices), std::move(clipped));
}

// Angle of the line through the pencil's point and x, in the pencil's 1-D coordinates.
double PencilAngle(const PencilBasis& pencil, const Eigen::Vector2d& x) {
  const Eigen::Vector2d c = pencil.Coordinates(pencil.e.cross(x.homogeneous()));
  return std::atan2(c.y(), c.x());
}

// The touch point of tangent `side` of view j's hull at frame `index`, if usable and valid.
std::optional<Eigen::Vector2d> TouchPoint(const SilhouetteSequence& j, int64_t index,
                                          const Eigen::Vector3d& epipole, int side) {
  if (index < 0) return std::nullopt;
  const SilhouetteFrame* f = j.Usable(static_cast<uint64_t>(index));
  if (f == nullptr) return std::nullopt;
  const OuterTangents t = ComputeOuterTangents(f->hull, epipole);
  if (!t.exists || !t.valid[side]) return std::nullopt;
  return t.point[side];
}

// View j's frontier point at the match's fractional time: the tangent line's angle about the
// epipole by Catmull-Rom interpolation over frames a - 1 .. a + 2 (linear where the outer
// frames are missing), the point the linear interpolation of the touch points projected onto
// that line. Cubic interpolation follows limbs that accelerate between frames.
Eigen::Vector2d InterpolateFrontierPoint(const SilhouetteSequence& j, const TimedMatch& m,
                                         double offset, const PencilBasis& pencil) {
  const Eigen::Vector2d linear = m.XjAt(offset);
  const double f = m.Fraction(offset);
  if (f <= 0.0) return linear;
  const auto a = static_cast<int64_t>(m.frame_j);
  const auto before = TouchPoint(j, a - 1, pencil.e, m.partner);
  const auto after = TouchPoint(j, a + 2, pencil.e, m.partner);
  if (!before || !after) return linear;
  const double p1 = PencilAngle(pencil, m.x_j_a);
  // Lines are unoriented: bring every angle within a quarter turn of p1.
  const auto near = [&](double angle) { return p1 + std::remainder(angle - p1, std::numbers::pi); };
  const double p0 = near(PencilAngle(pencil, *before));
  const double p2 = near(PencilAngle(pencil, m.x_j_b));
  const double p3 = near(PencilAngle(pencil, *after));
  const double angle =
      0.5 * (2.0 * p1 + (p2 - p0) * f + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * f * f +
             (3.0 * p1 - p0 - 3.0 * p2 + p3) * f * f * f);
  const Eigen::Vector3d line = pencil.Line({std::cos(angle), std::sin(angle)});
  const double norm2 = line.head<2>().squaredNorm();
  if (norm2 < 1e-300) return linear;
  return linear - (line.dot(linear.homogeneous()) / norm2) * line.head<2>();
}

}  // namespace

Eigen::Vector2d DistortPixel(const CameraModel& camera, const Eigen::Vector2d& undistorted) {
  if (!camera.HasDistortion()) return undistorted;
  const Eigen::Vector3d n = camera.K.inverse() * undistorted.homogeneous();
  return (camera.K * camera.Distort(n.hnormalized()).homogeneous()).hnormalized();
}

SilhouetteSequence UndistortSequence(const SilhouetteSequence& sequence,
                                     const CameraModel& camera) {
  SilhouetteSequence out = sequence;
  if (!camera.HasDistortion()) return out;
  for (SilhouetteFrame& f : out.frames) {
    if (!f.hull.empty()) f.hull = UndistortHull(f.hull, camera);
  }
  out.Index();
  return out;
}

std::vector<Correspondence> RematchFrontierPoints(const SilhouetteSequence& undistorted_i,
                                                  const SilhouetteSequence& undistorted_j,
                                                  const CameraModel& camera_i,
                                                  const CameraModel& camera_j, double offset) {
  const EpipolarModel model =
      EpipolarModel::FromFundamental(FundamentalFromCameras(camera_i, camera_j), offset);
  const std::vector<TimedMatch> matches =
      MatchAllFrames(model, undistorted_i, undistorted_j, UsableFrames(undistorted_i));
  std::vector<Correspondence> out;
  out.reserve(matches.size());
  for (const TimedMatch& m : matches) {
    const Eigen::Vector2d x_j = InterpolateFrontierPoint(undistorted_j, m, offset, model.pencil_j);
    out.push_back({DistortPixel(camera_i, m.x_i), DistortPixel(camera_j, x_j), m.frame_i});
  }
  return out;
}

}  // namespace silnet::aggregator

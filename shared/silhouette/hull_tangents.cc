#include "shared/silhouette/hull_tangents.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "shared/util/check.h"

namespace silnet {
namespace {

// Orientation of (p, a, b) with p homogeneous (w >= 0): > 0 when b is counter-clockwise
// from a as seen from p (for w = 0: b lies further along the left normal of (x, y)).
double OrientFrom(const Eigen::Vector3d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return p.x() * (a.y() - b.y()) - p.y() * (a.x() - b.x()) +
         p.z() * (a.x() * b.y() - a.y() * b.x());
}

// The vertex that is extreme in the angular order seen from p: the maximum for sign = +1
// (all other vertices clockwise from it), the minimum for sign = -1. Binary search over the
// cyclic bitonic sequence of angles; see the case analysis below. A returned vertex is
// locally extreme (both its edges fall back in the order: IsExtreme holds); -1 when the
// search finds none (p on or inside the hull, collinear vertices). Indices stay in [0, n]
// (n wraps to 0), and whether the lower bound's edge rises is carried along, so a step costs
// one or two orientations.
int ExtremeVertex(const std::vector<Eigen::Vector2d>& v, const Eigen::Vector3d& p, double sign) {
  const int n = static_cast<int>(v.size());
  auto vertex = [&](int i) -> const Eigen::Vector2d& {
    return v[static_cast<size_t>(i < n ? i : i - n)];
  };
  // later(a, b): vertex b comes after vertex a in the order.
  auto later = [&](int a, int b) { return sign * OrientFrom(p, vertex(a), vertex(b)) > 0.0; };
  auto up = [&](int i) { return later(i, i + 1); };  // edge i moves forward in the order
  const bool up_first = up(0);
  if (!up_first && up(n - 1)) return 0;
  int a = 0, b = n;
  bool up_a = up_first;
  // Invariant: the extreme vertex lies strictly between a and b (so b - a >= 2).
  for (int guard = 0; guard < 64 && b - a >= 2; ++guard) {
    const int c = (a + b) / 2;
    const bool up_c = up(c);
    if (!up_c && up(c - 1)) return c;
    bool c_becomes_a;
    if (up_a) {
      // a rises towards the extreme: it lies after a, before c unless c rises on the same run.
      c_becomes_a = up_c && !later(c, a);
    } else {
      // a falls away from the extreme: it lies after c if c rises or falls on a's run.
      c_becomes_a = up_c || later(c, a);
    }
    if (c_becomes_a) {
      a = c;
      up_a = up_c;
    } else {
      b = c;
    }
  }
  return -1;
}

bool IsExtreme(const std::vector<Eigen::Vector2d>& v, const Eigen::Vector3d& p, double sign,
               int i) {
  const int n = static_cast<int>(v.size());
  if (i < 0) return false;
  const Eigen::Vector2d& x = v[static_cast<size_t>(i)];
  return sign * OrientFrom(p, x, v[static_cast<size_t>((i + 1) % n)]) <= 0.0 &&
         sign * OrientFrom(p, x, v[static_cast<size_t>((i + n - 1) % n)]) <= 0.0;
}

Eigen::Vector3d NormalizedPoint(const Eigen::Vector3d& point) {
  return point.z() < 0.0 ? Eigen::Vector3d(-point) : point;
}

bool Outside(const SilhouetteHull& hull, const Eigen::Vector3d& p) {
  const auto& v = hull.vertices();
  for (size_t i = 0; i < v.size(); ++i) {
    // p strictly right of a directed edge (the hull is on the left): outside.
    if (OrientFrom(p, v[i], v[(i + 1) % v.size()]) < 0.0) return true;
  }
  return false;
}

}  // namespace

int SupportingVertex(const SilhouetteHull& hull, double angle) {
  SILNET_CHECK(!hull.empty());
  const std::vector<double>& table = hull.edge_angles();
  const int n = hull.size();
  angle = std::fmod(angle, 2.0 * std::numbers::pi);
  if (angle < 0.0) angle += 2.0 * std::numbers::pi;
  // The table is sorted up to a rotation; find where it starts (smallest angle).
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (table[static_cast<size_t>(mid)] > table[static_cast<size_t>(hi)]) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  const int start = lo;
  // First edge (in sorted order) with angle >= `angle`; its start vertex is the answer.
  int count = n, first = 0;
  while (count > 0) {
    const int step = count / 2;
    const int index = (start + first + step) % n;
    if (table[static_cast<size_t>(index)] < angle) {
      first += step + 1;
      count -= step + 1;
    } else {
      count = step;
    }
  }
  return (start + first) % n;
}

std::optional<PointTangents> TangentsFromPointLinear(const SilhouetteHull& hull,
                                                     const Eigen::Vector3d& point) {
  if (hull.size() < 3) return std::nullopt;
  const Eigen::Vector3d p = NormalizedPoint(point);
  if (!Outside(hull, p)) return std::nullopt;
  PointTangents t;
  for (int i = 0; i < hull.size(); ++i) {
    if (t.right < 0 && IsExtreme(hull.vertices(), p, 1.0, i)) t.right = i;
    if (t.left < 0 && IsExtreme(hull.vertices(), p, -1.0, i)) t.left = i;
  }
  return t;
}

std::optional<PointTangents> TangentsFromPoint(const SilhouetteHull& hull,
                                               const Eigen::Vector3d& point) {
  if (hull.size() < 3) return std::nullopt;
  const Eigen::Vector3d p = NormalizedPoint(point);
  PointTangents t;
  t.right = ExtremeVertex(hull.vertices(), p, 1.0);
  t.left = ExtremeVertex(hull.vertices(), p, -1.0);
  // A vertex ExtremeVertex returns is locally extreme (IsExtreme holds by construction).
  if (t.left >= 0 && t.right >= 0 && t.left != t.right &&
      OrientFrom(p, hull.vertex(t.left), hull.vertex(t.right)) > 0.0) {
    return t;
  }
  return TangentsFromPointLinear(hull, point);
}

Eigen::Vector3d TangentLine(const SilhouetteHull& hull, const Eigen::Vector3d& point, int vertex) {
  return point.cross(hull.vertex(vertex).homogeneous());
}

}  // namespace silnet

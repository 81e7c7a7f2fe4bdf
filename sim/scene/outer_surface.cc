#include "sim/scene/outer_surface.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "shared/util/check.h"

namespace silnet::sim {
namespace {

Eigen::Vector3d RandomUnitVector(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d u;
  do {
    u = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  } while (u.squaredNorm() < 1e-12);
  return u.normalized();
}

// Capsule: the cylinder's side or one of the two outward hemispheres, chosen by area.
Eigen::Vector3d CapsulePoint(const Primitive& p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const Eigen::Vector3d ab = p.b - p.a;
  const double length = ab.norm();
  const double side = 2.0 * std::numbers::pi * p.radius * length;
  const double caps = 4.0 * std::numbers::pi * p.radius * p.radius;
  const Eigen::Vector3d axis =
      length > 0.0 ? Eigen::Vector3d(ab / length) : Eigen::Vector3d::UnitZ();
  if (uniform(rng) * (side + caps) < side) {
    const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
    const double angle = 2.0 * std::numbers::pi * uniform(rng);
    return p.a + uniform(rng) * ab + p.radius * (std::cos(angle) * e1 + std::sin(angle) * e2);
  }
  Eigen::Vector3d u = RandomUnitVector(rng);
  const bool at_b = uniform(rng) < 0.5;
  const double along = u.dot(axis);
  // Fold the direction onto the outward hemisphere of the chosen end.
  if ((at_b && along < 0.0) || (!at_b && along > 0.0)) u -= 2.0 * along * axis;
  return (at_b ? p.b : p.a) + p.radius * u;
}

// Ellipsoid: a uniform sphere direction mapped onto the ellipsoid, accepted in proportion
// to the area stretch |u / radii| (rejection sampling; acceptance >= min/max radius).
Eigen::Vector3d EllipsoidPoint(const Primitive& p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double smallest = p.radii.minCoeff();
  for (;;) {
    const Eigen::Vector3d u = RandomUnitVector(rng);
    if (uniform(rng) <= u.cwiseQuotient(p.radii).norm() * smallest) {
      return p.center + p.axes * u.cwiseProduct(p.radii);
    }
  }
}

}  // namespace

std::vector<Eigen::Vector3d> SampleSurfaceUniformly(const Primitive& primitive, int count,
                                                    std::mt19937_64& rng) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<size_t>(std::max(count, 0)));
  for (int i = 0; i < count; ++i) {
    points.push_back(primitive.kind == PrimitiveKind::kCapsule ? CapsulePoint(primitive, rng)
                                                               : EllipsoidPoint(primitive, rng));
  }
  return points;
}

std::vector<SurfacePoint> SampleOuterSurface(const std::vector<Primitive>& primitives,
                                             double spacing, uint64_t seed) {
  SILNET_CHECK(spacing > 0.0);
  std::mt19937_64 rng(seed);
  std::vector<SurfacePoint> out;
  for (size_t i = 0; i < primitives.size(); ++i) {
    const Primitive& p = primitives[i];
    const int count = static_cast<int>(std::lround(p.SurfaceArea() / (spacing * spacing)));
    // Only primitives whose bounding spheres meet this one can hide part of its surface.
    std::vector<const Primitive*> neighbours;
    for (size_t j = 0; j < primitives.size(); ++j) {
      const Primitive& q = primitives[j];
      if (j != i && (q.BoundingCenter() - p.BoundingCenter()).norm() <
                        q.BoundingRadius() + p.BoundingRadius()) {
        neighbours.push_back(&q);
      }
    }
    for (const Eigen::Vector3d& x : SampleSurfaceUniformly(p, count, rng)) {
      const bool hidden = std::any_of(neighbours.begin(), neighbours.end(),
                                      [&](const Primitive* q) { return q->Contains(x); });
      if (!hidden) out.push_back({x, p.Normal(x)});
    }
  }
  return out;
}

}  // namespace silnet::sim

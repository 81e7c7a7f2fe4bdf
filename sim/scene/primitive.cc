#include "sim/scene/primitive.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace silnet::sim {
namespace {

// Smallest root t > 0 of a t^2 + 2 b t + c = 0 (half-b form), if any.
bool SmallestPositiveRoot(double a, double half_b, double c, double* t) {
  const double disc = half_b * half_b - a * c;
  if (disc < 0.0 || a <= 0.0) return false;
  const double s = std::sqrt(disc);
  const double t0 = (-half_b - s) / a;
  const double t1 = (-half_b + s) / a;
  if (t0 > 0.0) {
    *t = t0;
    return true;
  }
  if (t1 > 0.0) {
    *t = t1;
    return true;
  }
  return false;
}

}  // namespace

Primitive Primitive::MakeCapsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                                 const Eigen::Matrix3d& frame, int part, int material) {
  Primitive p;
  p.kind = PrimitiveKind::kCapsule;
  p.a = a;
  p.b = b;
  p.radius = radius;
  p.center = 0.5 * (a + b);
  p.axes = frame;
  p.part = part;
  p.material = material;
  return p;
}

Primitive Primitive::MakeEllipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& radii,
                                   const Eigen::Matrix3d& axes, int part, int material) {
  Primitive p;
  p.kind = PrimitiveKind::kEllipsoid;
  p.center = center;
  p.radii = radii;
  p.axes = axes;
  p.part = part;
  p.material = material;
  return p;
}

Primitive Primitive::Transformed(const Eigen::Matrix3d& rotation,
                                 const Eigen::Vector3d& translation) const {
  Primitive p = *this;
  p.a = rotation * a + translation;
  p.b = rotation * b + translation;
  p.center = rotation * center + translation;
  p.axes = rotation * axes;
  return p;
}

Eigen::Vector3d Primitive::BoundingCenter() const {
  return center;
}

double Primitive::BoundingRadius() const {
  if (kind == PrimitiveKind::kCapsule) return 0.5 * (b - a).norm() + radius;
  return radii.maxCoeff();
}

Eigen::Vector3d Primitive::HalfExtents() const {
  if (kind == PrimitiveKind::kCapsule) {
    return 0.5 * (b - a).cwiseAbs() + Eigen::Vector3d::Constant(radius);
  }
  const Eigen::Matrix3d scaled = axes * radii.asDiagonal();
  return scaled.rowwise().norm();
}

double Primitive::SurfaceArea() const {
  if (kind == PrimitiveKind::kCapsule) {
    return 2.0 * std::numbers::pi * radius * (b - a).norm() +
           4.0 * std::numbers::pi * radius * radius;
  }
  constexpr double p = 1.6075;
  const double ap = std::pow(radii.x(), p), bp = std::pow(radii.y(), p),
               cp = std::pow(radii.z(), p);
  return 4.0 * std::numbers::pi * std::pow((ap * bp + ap * cp + bp * cp) / 3.0, 1.0 / p);
}

bool Primitive::Contains(const Eigen::Vector3d& point) const {
  if (kind == PrimitiveKind::kCapsule) {
    const Eigen::Vector3d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double s = len2 > 0 ? std::clamp((point - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (point - (a + s * ab)).squaredNorm() <= radius * radius;
  }
  const Eigen::Vector3d local = (axes.transpose() * (point - center)).cwiseQuotient(radii);
  return local.squaredNorm() <= 1.0;
}

Eigen::Vector3d Primitive::LocalPoint(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d& origin = kind == PrimitiveKind::kCapsule ? a : center;
  return axes.transpose() * (point - origin);
}

Eigen::Vector3d Primitive::Normal(const Eigen::Vector3d& surface_point) const {
  if (kind == PrimitiveKind::kCapsule) {
    const Eigen::Vector3d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double s = len2 > 0 ? std::clamp((surface_point - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (surface_point - (a + s * ab)).normalized();
  }
  const Eigen::Vector3d local = axes.transpose() * (surface_point - center);
  const Eigen::Vector3d gradient = local.cwiseQuotient(radii.cwiseProduct(radii));
  return (axes * gradient).normalized();
}

bool Primitive::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                          double* t) const {
  if (kind == PrimitiveKind::kEllipsoid) {
    const Eigen::Vector3d o = (axes.transpose() * (origin - center)).cwiseQuotient(radii);
    const Eigen::Vector3d d = (axes.transpose() * dir).cwiseQuotient(radii);
    return SmallestPositiveRoot(d.squaredNorm(), o.dot(d), o.squaredNorm() - 1.0, t);
  }
  // Capsule: the infinite cylinder first, accepted where the hit lies between the caps,
  // otherwise the nearer cap sphere (Quilez's formulation, unit-length dir).
  const Eigen::Vector3d ba = b - a;
  const Eigen::Vector3d oa = origin - a;
  const double baba = ba.squaredNorm();
  const double bard = ba.dot(dir);
  const double baoa = ba.dot(oa);
  const double rdoa = dir.dot(oa);
  const double oaoa = oa.squaredNorm();
  const double qa = baba - bard * bard;
  const double qb = baba * rdoa - baoa * bard;
  const double qc = baba * oaoa - baoa * baoa - radius * radius * baba;
  const double h = qb * qb - qa * qc;
  if (h < 0.0) return false;
  bool found = false;
  double best = 0.0;
  if (qa > 1e-12) {
    const double root = std::sqrt(h);
    for (double candidate : {(-qb - root) / qa, (-qb + root) / qa}) {
      const double y = baoa + candidate * bard;
      if (candidate > 0.0 && y > 0.0 && y < baba && (!found || candidate < best)) {
        best = candidate;
        found = true;
      }
    }
  }
  for (const Eigen::Vector3d* cap : {&a, &b}) {
    const Eigen::Vector3d oc = origin - *cap;
    double candidate = 0.0;
    if (SmallestPositiveRoot(1.0, dir.dot(oc), oc.squaredNorm() - radius * radius, &candidate) &&
        (!found || candidate < best)) {
      best = candidate;
      found = true;
    }
  }
  if (found) *t = best;
  return found;
}

std::vector<Eigen::Vector3d> Primitive::SampleSurface(int count, std::mt19937_64& rng) const {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d u(normal(rng), normal(rng), normal(rng));
    u.normalize();
    if (kind == PrimitiveKind::kEllipsoid) {
      points.push_back(center + axes * u.cwiseProduct(radii));
    } else {
      // A point on the segment plus a random direction: on the surface if the direction is
      // outward; samples that fall inside the other part of the capsule are pushed out.
      const Eigen::Vector3d on_axis = a + uniform(rng) * (b - a);
      Eigen::Vector3d p = on_axis + radius * u;
      const Eigen::Vector3d ab = b - a;
      const double len2 = ab.squaredNorm();
      const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
      const Eigen::Vector3d nearest = a + s * ab;
      p = nearest + radius * (p - nearest).normalized();
      points.push_back(p);
    }
  }
  return points;
}

bool AnyContains(const std::vector<Primitive>& primitives, const Eigen::Vector3d& point) {
  for (const Primitive& p : primitives) {
    if (p.Contains(point)) return true;
  }
  return false;
}

}  // namespace silnet::sim

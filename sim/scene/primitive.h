#pragma once
// The convex solids simulated subjects are built from: capsules (sphere-swept segments) and
// ellipsoids. Each carries a texture frame that moves with its body part, so surface
// texture sticks to the limb, and a material index.

#include <Eigen/Core>
#include <random>
#include <vector>

namespace silnet::sim {

enum class PrimitiveKind { kCapsule, kEllipsoid };

// One convex solid in some frame (world or camera).
struct Primitive {
  PrimitiveKind kind = PrimitiveKind::kEllipsoid;
  // Capsule: the segment a-b swept by a sphere of `radius`.
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0.0;
  // Ellipsoid: centre, semi-axes along the columns of `axes`.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();
  // Both kinds: orthonormal frame (columns = local axes) used for the ellipsoid's axes and
  // for texture coordinates; origin is `center` for ellipsoids and `a` for capsules.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  int subject = 0;   // index of the subject in its scene
  int part = 0;      // body part id (see the subject's part names)
  int material = 0;  // index into the scene's materials

  static Primitive MakeCapsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                               const Eigen::Matrix3d& frame, int part, int material);
  static Primitive MakeEllipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& radii,
                                 const Eigen::Matrix3d& axes, int part, int material);

  // The same solid after x -> rotation * x + translation.
  Primitive Transformed(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation) const;
  // Centre and radius of a sphere containing the solid.
  Eigen::Vector3d BoundingCenter() const;
  double BoundingRadius() const;
  // Half sizes of the smallest axis-aligned box around the solid, centred on BoundingCenter().
  Eigen::Vector3d HalfExtents() const;
  // Surface area, m^2 (ellipsoids by Thomsen's approximation, within about 1 %).
  double SurfaceArea() const;
  // True if the point lies inside or on the solid.
  bool Contains(const Eigen::Vector3d& point) const;
  // Texture-frame coordinates of a point (relative to the frame origin, in local axes).
  Eigen::Vector3d LocalPoint(const Eigen::Vector3d& point) const;
  // Outward unit normal at a surface point.
  Eigen::Vector3d Normal(const Eigen::Vector3d& surface_point) const;
  // Distance t > 0 along the unit direction `dir` from `origin` to the first surface hit
  // (the far side if the origin is inside); false if the ray misses.
  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double* t) const;
  // `count` points spread over the surface, for ground-truth checks.
  std::vector<Eigen::Vector3d> SampleSurface(int count, std::mt19937_64& rng) const;
};

// True if `point` lies inside any of the primitives.
bool AnyContains(const std::vector<Primitive>& primitives, const Eigen::Vector3d& point);

}  // namespace silnet::sim

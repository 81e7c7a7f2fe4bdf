#pragma once
// Dense ground truth of a solid made of primitives: points spread uniformly by area over
// the boundary of their union (the true outer surface), each with its outward normal. A
// point of one primitive's surface belongs to the union's boundary iff no other primitive
// contains it. Cavities fully enclosed by the union would count as surface too; the
// simulator's subjects have none.

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "sim/scene/primitive.h"

namespace silnet::sim {

// A surface point and its outward unit normal, world frame, metres.
struct SurfacePoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// `count` points spread uniformly by area over the surface of `primitive` (unlike
// Primitive::SampleSurface, which favours a capsule's caps and an ellipsoid's flat sides).
std::vector<Eigen::Vector3d> SampleSurfaceUniformly(const Primitive& primitive, int count,
                                                    std::mt19937_64& rng);

// Points on the outer surface of the union of `primitives`, about one per spacing^2 of
// area (spacing in metres, > 0), in primitive order. Deterministic for a seed.
std::vector<SurfacePoint> SampleOuterSurface(const std::vector<Primitive>& primitives,
                                             double spacing, uint64_t seed);

}  // namespace silnet::sim

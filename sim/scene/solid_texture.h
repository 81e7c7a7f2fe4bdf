#pragma once
// Procedural solid textures: deterministic functions of a 3D point, so a surface looks the
// same from every camera (Lambertian, photo-consistent) and needs no UV mapping.

#include <Eigen/Core>
#include <cstdint>

namespace silnet::sim {

// Smooth value noise in [0, 1] with unit lattice spacing, seeded.
double ValueNoise(const Eigen::Vector3d& p, uint32_t seed);

// Sum of `octaves` value-noise layers with halving amplitude and doubling frequency, in
// [0, 1]; `scale` is the size in metres of the coarsest features.
double FractalNoise(const Eigen::Vector3d& p, double scale, int octaves, uint32_t seed);

// How a surface is coloured: a base colour modulated by noise and optional stripes.
struct Material {
  Eigen::Vector3d albedo{0.5, 0.5, 0.5};  // linear RGB in [0, 1]
  Eigen::Vector3d second{0.3, 0.3, 0.3};  // colour mixed in by the pattern
  double noise_amplitude = 0.15;          // relative brightness variation
  double noise_scale = 0.05;              // metres
  double stripe_period = 0.0;             // metres along local z; 0 = no stripes
  uint32_t seed = 1;

  // Albedo (RGB, [0, 1]) at a point given in the primitive's texture frame.
  Eigen::Vector3d ColorAt(const Eigen::Vector3d& local_point) const;
};

}  // namespace silnet::sim

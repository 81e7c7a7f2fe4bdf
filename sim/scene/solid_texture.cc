#include "sim/scene/solid_texture.h"

#include <algorithm>
#include <cmath>

namespace silnet::sim {
namespace {

// Integer hash of a lattice point (a variant of the PCG output permutation).
uint32_t HashLattice(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  uint32_t h = seed * 0x9E3779B9u;
  h ^= static_cast<uint32_t>(x) * 0x85EBCA6Bu;
  h = (h << 13) | (h >> 19);
  h ^= static_cast<uint32_t>(y) * 0xC2B2AE35u;
  h = (h << 17) | (h >> 15);
  h ^= static_cast<uint32_t>(z) * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  h ^= h >> 16;
  return h;
}

double LatticeValue(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  return static_cast<double>(HashLattice(x, y, z, seed)) / 4294967295.0;
}

double Smooth(double t) {
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace

double ValueNoise(const Eigen::Vector3d& p, uint32_t seed) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const auto x = static_cast<int32_t>(fx), y = static_cast<int32_t>(fy),
             z = static_cast<int32_t>(fz);
  const double tx = Smooth(p.x() - fx), ty = Smooth(p.y() - fy), tz = Smooth(p.z() - fz);
  double corners[2][2][2];
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx)
        corners[dz][dy][dx] = LatticeValue(x + dx, y + dy, z + dz, seed);
  auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double c00 = lerp(corners[0][0][0], corners[0][0][1], tx);
  const double c01 = lerp(corners[0][1][0], corners[0][1][1], tx);
  const double c10 = lerp(corners[1][0][0], corners[1][0][1], tx);
  const double c11 = lerp(corners[1][1][0], corners[1][1][1], tx);
  return lerp(lerp(c00, c01, ty), lerp(c10, c11, ty), tz);
}

double FractalNoise(const Eigen::Vector3d& p, double scale, int octaves, uint32_t seed) {
  double sum = 0.0, weight = 0.0, amplitude = 1.0, frequency = 1.0 / scale;
  for (int octave = 0; octave < octaves; ++octave) {
    sum += amplitude * ValueNoise(p * frequency, seed + static_cast<uint32_t>(octave) * 7919u);
    weight += amplitude;
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return sum / weight;
}

Eigen::Vector3d Material::ColorAt(const Eigen::Vector3d& local_point) const {
  const double n = FractalNoise(local_point, noise_scale, 3, seed);
  Eigen::Vector3d colour = albedo;
  if (stripe_period > 0.0) {
    const double phase = local_point.z() / stripe_period;
    const double stripe = 0.5 + 0.5 * std::sin(2.0 * 3.14159265358979 * phase);
    colour = albedo + (second - albedo) * Smooth(std::clamp(stripe * 1.6 - 0.3, 0.0, 1.0));
  } else {
    colour = albedo + (second - albedo) * Smooth(std::clamp(2.0 * n - 0.5, 0.0, 1.0));
  }
  const double brightness = 1.0 + noise_amplitude * (2.0 * n - 1.0);
  return (colour * brightness).cwiseMax(0.0).cwiseMin(1.0);
}

}  // namespace silnet::sim

#include "sim/render/sensor_noise.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace silnet::sim {

uint64_t MixSeed(uint64_t a, uint64_t b, uint64_t c) {
  auto mix = [](uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  };
  return mix(mix(mix(a) ^ b) ^ c);
}

SensorNoise::SensorNoise(double sigma, std::size_t values_per_image, uint64_t seed)
    : sigma_(sigma), values_per_image_(values_per_image) {
  table_.resize(2 * values_per_image + 4096);
  if (sigma <= 0.0) return;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  for (int8_t& v : table_)
    v = static_cast<int8_t>(std::clamp(std::lround(normal(rng)), -127l, 127l));
}

const int8_t* SensorNoise::ForImage(uint64_t image_seed) const {
  const std::size_t span = table_.size() - values_per_image_;
  return table_.data() + (MixSeed(image_seed, 0x51u) % span);
}

}  // namespace silnet::sim

#pragma once
// Gaussian sensor noise, fast: a table of pre-drawn N(0, sigma) samples read from a
// pseudo-random offset per image, so adding noise costs one pass over the pixels.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace silnet::sim {

// Pre-drawn Gaussian noise in digital numbers (DN).
class SensorNoise {
 public:
  // `values_per_image` is the number of samples one image needs (width * height * channels).
  SensorNoise(double sigma, std::size_t values_per_image, uint64_t seed);

  // `values_per_image` noise samples for the image identified by `image_seed`; the same seed
  // gives the same samples.
  const int8_t* ForImage(uint64_t image_seed) const;
  double sigma() const { return sigma_; }
  std::size_t values_per_image() const { return values_per_image_; }

 private:
  double sigma_;
  std::size_t values_per_image_;
  std::vector<int8_t> table_;
};

// A well-mixed 64-bit hash of several integers (splitmix64 chain).
uint64_t MixSeed(uint64_t a, uint64_t b, uint64_t c = 0);

}  // namespace silnet::sim

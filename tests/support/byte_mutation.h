#pragma once
// Deterministic mutations of valid inputs for the readers' robustness tests: the edits a
// fuzzer starts with (bit flips, random bytes, truncations, insertions), reproducible from
// the generator's seed.

#include <cstdint>
#include <random>
#include <vector>

namespace silnet::testing {

// `seed` with one to four random edits, each a flipped bit, a replaced byte, the rest cut off
// at a random place, or an inserted byte.
std::vector<uint8_t> MutateBytes(const std::vector<uint8_t>& seed, std::mt19937& random);

}  // namespace silnet::testing

#include "tests/support/byte_mutation.h"

namespace silnet::testing {

std::vector<uint8_t> MutateBytes(const std::vector<uint8_t>& seed, std::mt19937& random) {
  std::vector<uint8_t> bytes = seed;
  const int edits = 1 + static_cast<int>(random() % 4);
  for (int e = 0; e < edits && !bytes.empty(); ++e) {
    const size_t at = random() % bytes.size();
    switch (random() % 4) {
      case 0:
        bytes[at] ^= static_cast<uint8_t>(1u << (random() % 8));
        break;
      case 1:
        bytes[at] = static_cast<uint8_t>(random());
        break;
      case 2:
        bytes.resize(at);
        break;
      default:
        bytes.insert(bytes.begin() + static_cast<long>(at), static_cast<uint8_t>(random()));
    }
  }
  return bytes;
}

}  // namespace silnet::testing

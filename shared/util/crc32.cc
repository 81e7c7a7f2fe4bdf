#include "shared/util/crc32.h"

#include <zlib.h>

#include <algorithm>

namespace silnet {

uint32_t Crc32(uint32_t crc, const uint8_t* data, std::size_t size) {
  uLong value = crc;
  while (size > 0) {
    const std::size_t part = std::min<std::size_t>(size, std::size_t{1} << 30);
    value = crc32(value, data, static_cast<uInt>(part));
    data += part;
    size -= part;
  }
  return static_cast<uint32_t>(value);
}

}  // namespace silnet

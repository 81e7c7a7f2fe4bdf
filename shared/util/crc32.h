#pragma once
// CRC-32 as zlib computes it (ISO-HDLC / IEEE 802.3 polynomial, initial value 0), for any
// length: session records and still chunks are checked with it.

#include <cstddef>
#include <cstdint>

namespace silnet {

// Continues the CRC-32 `crc` (0 to start) over `size` bytes at `data`.
uint32_t Crc32(uint32_t crc, const uint8_t* data, std::size_t size);

}  // namespace silnet

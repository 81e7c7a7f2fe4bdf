#pragma once
// The wire encoding of SilhouetteContours (the Contour payload). Byte layout, little-endian:
//   u8      version (1)
//   varint  polygon count
//   per polygon: varint hole count h, then 1 + h rings: varint point count n (>= 3), the first
//           point as two zigzag varints of round((c + 0.5) * 8), then n - 1 deltas of those
//           quantised coordinates as zigzag varints
//   u32     CRC-32 (zlib) of everything before it
// Coordinates are rounded to 1/8 px.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "shared/silhouette/silhouette_contour.h"

namespace silnet {

inline constexpr size_t kMaxContourPoints = 1 << 20;

// Encodes contours; coordinates are rounded to 1/8 px.
std::vector<uint8_t> EncodeContours(const SilhouetteContours& contours);

// Decodes and validates bytes for an image of `width` x `height` (CRC, counts, points within
// the image, at most kMaxContourPoints in all). Returns false with a reason on failure;
// never reads out of bounds or allocates more than the data can describe.
bool DecodeContours(std::span<const uint8_t> bytes, int width, int height,
                    SilhouetteContours* contours, std::string* error);

}  // namespace silnet

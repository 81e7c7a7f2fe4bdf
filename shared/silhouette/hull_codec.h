#pragma once
// The compact wire encoding of a SilhouetteHull (the HullFrame payload): under 300 bytes
// for a 40-vertex hull. Byte layout, little-endian:
//   u8      version (1)
//   varint  vertex count k (<= kMaxHullVertices)
//   varint  foreground pixel count
//   k x     u16 x, u16 y: vertex coordinates as round((c + 0.5) * 16), 1/16 px steps
//   ceil(k/8) bytes of clipped-edge bits, edge i in bit i % 8 of byte i / 8
//   k x     u16 tangent table: edge angle * 65536 / (2 pi), rounded, mod 65536
//   u32     CRC-32 (zlib) of everything before it
// Vertices from ComputeSilhouetteHull lie on half pixels, so they round-trip exactly.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "shared/silhouette/silhouette_hull.h"

namespace silnet {

inline constexpr int kMaxHullVertices = 1024;

// A hull and the silhouette facts sent with it.
struct HullPayload {
  SilhouetteHull hull;
  int foreground_pixels = 0;
};

// Encodes a payload. Vertices are rounded to 1/16 px and must lie in [-0.5, 4095.4];
// throws CheckError otherwise or if the hull has more than kMaxHullVertices vertices.
std::vector<uint8_t> EncodeHull(const HullPayload& payload);

// Decodes and validates bytes for an image of `width` x `height`: version, lengths, CRC,
// vertices inside the image, a strictly convex hull in positive orientation, clipped edges
// on the border, and a tangent table consistent with the vertices. On failure returns false
// with a one-line reason in `error`; never reads out of bounds.
bool DecodeHull(std::span<const uint8_t> bytes, int width, int height, HullPayload* payload,
                std::string* error);

}  // namespace silnet

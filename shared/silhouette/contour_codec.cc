#include "shared/silhouette/contour_codec.h"

#include <zlib.h>

#include <cmath>

#include "shared/util/byte_io.h"

namespace silnet {
namespace {

constexpr uint8_t kVersion = 1;
constexpr float kScale = 8.0f;

int64_t Quantize(float c) {
  return std::lround((c + 0.5f) * kScale);
}
float Dequantize(int64_t q) {
  return static_cast<float>(q) / kScale - 0.5f;
}

uint32_t Crc(std::span<const uint8_t> bytes) {
  return static_cast<uint32_t>(crc32(0L, bytes.data(), static_cast<uInt>(bytes.size())));
}

void PutRing(ByteWriter* out, const std::vector<Eigen::Vector2f>& ring) {
  out->PutVarint(ring.size());
  int64_t px = 0, py = 0;
  for (const Eigen::Vector2f& p : ring) {
    const int64_t x = Quantize(p.x()), y = Quantize(p.y());
    out->PutSignedVarint(x - px);
    out->PutSignedVarint(y - py);
    px = x;
    py = y;
  }
}

bool Fail(std::string* error, const std::string& reason) {
  if (error != nullptr) *error = reason;
  return false;
}

}  // namespace

std::vector<uint8_t> EncodeContours(const SilhouetteContours& contours) {
  std::vector<uint8_t> bytes;
  bytes.reserve(16 + contours.PointCount() * 3);
  ByteWriter out(&bytes);
  out.PutU8(kVersion);
  out.PutVarint(contours.polygons.size());
  for (const ContourPolygon& polygon : contours.polygons) {
    out.PutVarint(polygon.holes.size());
    PutRing(&out, polygon.outer);
    for (const auto& hole : polygon.holes)
      PutRing(&out, hole);
  }
  out.PutU32(Crc(bytes));
  return bytes;
}

bool DecodeContours(std::span<const uint8_t> bytes, int width, int height,
                    SilhouetteContours* contours, std::string* error) {
  if (bytes.size() < 6) return Fail(error, "contour payload too short");
  const std::span<const uint8_t> body = bytes.first(bytes.size() - 4);
  ByteReader crc_reader(bytes.last(4));
  uint32_t crc = 0;
  crc_reader.GetU32(&crc);
  if (crc != Crc(body)) return Fail(error, "contour payload checksum mismatch");
  ByteReader in(body);
  uint8_t version = 0;
  if (!in.GetU8(&version) || version != kVersion)
    return Fail(error, "unknown contour encoding version");
  uint64_t polygon_count = 0;
  // Every ring takes at least 7 bytes, which bounds the counts by the data size.
  if (!in.GetVarint(&polygon_count) || polygon_count > in.remaining()) {
    return Fail(error, "bad contour polygon count");
  }
  size_t total = 0;
  SilhouetteContours result;
  auto get_ring = [&](std::vector<Eigen::Vector2f>* ring) {
    uint64_t n = 0;
    if (!in.GetVarint(&n) || n < 3 || n > in.remaining() || total + n > kMaxContourPoints)
      return false;
    total += n;
    ring->reserve(n);
    int64_t x = 0, y = 0;
    for (uint64_t i = 0; i < n; ++i) {
      int64_t dx = 0, dy = 0;
      if (!in.GetSignedVarint(&dx) || !in.GetSignedVarint(&dy)) return false;
      x += dx;
      y += dy;
      const float fx = Dequantize(x), fy = Dequantize(y);
      if (fx < -0.5f || fy < -0.5f || fx > width - 0.5f || fy > height - 0.5f) return false;
      ring->emplace_back(fx, fy);
    }
    return true;
  };
  for (uint64_t p = 0; p < polygon_count; ++p) {
    uint64_t holes = 0;
    if (!in.GetVarint(&holes) || holes > in.remaining())
      return Fail(error, "bad contour hole count");
    ContourPolygon polygon;
    if (!get_ring(&polygon.outer)) return Fail(error, "malformed contour ring");
    for (uint64_t h = 0; h < holes; ++h) {
      std::vector<Eigen::Vector2f> hole;
      if (!get_ring(&hole)) return Fail(error, "malformed contour hole");
      polygon.holes.push_back(std::move(hole));
    }
    result.polygons.push_back(std::move(polygon));
  }
  if (in.remaining() != 0) return Fail(error, "trailing bytes in contour payload");
  *contours = std::move(result);
  return true;
}

}  // namespace silnet

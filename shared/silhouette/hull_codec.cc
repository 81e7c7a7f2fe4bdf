#include "shared/silhouette/hull_codec.h"

#include <zlib.h>

#include <cmath>
#include <numbers>

#include "shared/silhouette/melkman_hull.h"
#include "shared/util/byte_io.h"
#include "shared/util/check.h"

namespace silnet {
namespace {

constexpr uint8_t kVersion = 1;
constexpr double kCoordinateScale = 1.0 / kHullVertexStep;

uint16_t QuantizeCoordinate(double c) {
  const double q = std::round((c + 0.5) * kCoordinateScale);
  SILNET_CHECK_MSG(q >= 0.0 && q <= 65535.0, "hull coordinate " << c << " out of range");
  return static_cast<uint16_t>(q);
}

double DequantizeCoordinate(uint16_t q) {
  return q / kCoordinateScale - 0.5;
}

uint16_t QuantizeAngle(double angle) {
  const long q = std::lround(angle * 65536.0 / (2.0 * std::numbers::pi));
  return static_cast<uint16_t>(q & 0xFFFF);
}

uint32_t Crc(std::span<const uint8_t> bytes) {
  return static_cast<uint32_t>(crc32(0L, bytes.data(), static_cast<uInt>(bytes.size())));
}

bool Fail(std::string* error, const std::string& reason) {
  if (error != nullptr) *error = reason;
  return false;
}

}  // namespace

std::vector<uint8_t> EncodeHull(const HullPayload& payload) {
  const SilhouetteHull& hull = payload.hull;
  SILNET_CHECK_MSG(hull.size() <= kMaxHullVertices, "hull has " << hull.size() << " vertices");
  std::vector<uint8_t> bytes;
  bytes.reserve(16 + static_cast<size_t>(hull.size()) * 6);
  ByteWriter out(&bytes);
  out.PutU8(kVersion);
  out.PutVarint(static_cast<uint64_t>(hull.size()));
  out.PutVarint(static_cast<uint64_t>(std::max(0, payload.foreground_pixels)));
  std::vector<Eigen::Vector2d> quantized;
  for (const Eigen::Vector2d& v : hull.vertices()) {
    const uint16_t x = QuantizeCoordinate(v.x()), y = QuantizeCoordinate(v.y());
    out.PutU16(x);
    out.PutU16(y);
    quantized.emplace_back(DequantizeCoordinate(x), DequantizeCoordinate(y));
  }
  for (int byte = 0; byte < (hull.size() + 7) / 8; ++byte) {
    uint8_t bits = 0;
    for (int bit = 0; bit < 8 && byte * 8 + bit < hull.size(); ++bit) {
      if (hull.edge_clipped(byte * 8 + bit)) bits |= static_cast<uint8_t>(1u << bit);
    }
    out.PutU8(bits);
  }
  // The table of the vertices as the decoder will see them.
  for (size_t i = 0; i < quantized.size(); ++i) {
    out.PutU16(QuantizeAngle(DirectionAngle(quantized[i], quantized[(i + 1) % quantized.size()])));
  }
  out.PutU32(Crc(bytes));
  return bytes;
}

bool DecodeHull(std::span<const uint8_t> bytes, int width, int height, HullPayload* payload,
                std::string* error) {
  if (bytes.size() < 7) return Fail(error, "hull payload too short");
  const std::span<const uint8_t> body = bytes.first(bytes.size() - 4);
  ByteReader crc_reader(bytes.last(4));
  uint32_t crc = 0;
  crc_reader.GetU32(&crc);
  if (crc != Crc(body)) return Fail(error, "hull payload checksum mismatch");
  ByteReader in(body);
  uint8_t version = 0;
  uint64_t count = 0, pixels = 0;
  if (!in.GetU8(&version) || version != kVersion) {
    return Fail(error, "unknown hull encoding version " + std::to_string(version));
  }
  if (!in.GetVarint(&count) || count > kMaxHullVertices)
    return Fail(error, "bad hull vertex count");
  if (!in.GetVarint(&pixels) ||
      pixels > static_cast<uint64_t>(width) * static_cast<uint64_t>(height)) {
    return Fail(error, "bad foreground pixel count");
  }
  const int k = static_cast<int>(count);
  if (in.remaining() != static_cast<size_t>(k) * 6 + static_cast<size_t>((k + 7) / 8)) {
    return Fail(error, "hull payload length does not match its vertex count");
  }
  if (k != 0 && k < 3) return Fail(error, "a hull needs at least 3 vertices");
  std::vector<Eigen::Vector2d> vertices(static_cast<size_t>(k));
  for (Eigen::Vector2d& v : vertices) {
    uint16_t x = 0, y = 0;
    in.GetU16(&x);
    in.GetU16(&y);
    v = {DequantizeCoordinate(x), DequantizeCoordinate(y)};
    if (v.x() > width - 0.5 || v.y() > height - 0.5)
      return Fail(error, "hull vertex outside the image");
  }
  std::vector<bool> clipped(static_cast<size_t>(k), false);
  for (int byte = 0; byte < (k + 7) / 8; ++byte) {
    uint8_t bits = 0;
    in.GetU8(&bits);
    for (int bit = 0; bit < 8 && byte * 8 + bit < k; ++bit) {
      clipped[static_cast<size_t>(byte * 8 + bit)] = (bits >> bit) & 1u;
    }
  }
  for (int i = 0; i < k; ++i) {
    const Eigen::Vector2d& a = vertices[static_cast<size_t>(i)];
    const Eigen::Vector2d& b = vertices[static_cast<size_t>((i + 1) % k)];
    const Eigen::Vector2d& c = vertices[static_cast<size_t>((i + 2) % k)];
    if (Orientation(a, b, c) <= 0.0)
      return Fail(error, "hull is not strictly convex in positive orientation");
    if (clipped[static_cast<size_t>(i)] &&
        !((a.x() == -0.5 && b.x() == -0.5) || (a.y() == -0.5 && b.y() == -0.5) ||
          (a.x() == width - 0.5 && b.x() == width - 0.5) ||
          (a.y() == height - 0.5 && b.y() == height - 0.5))) {
      return Fail(error, "clipped hull edge not on the image border");
    }
  }
  SilhouetteHull hull(std::move(vertices), std::move(clipped));
  // Winding once: the edge angles wrap around exactly once.
  int wraps = 0;
  for (int i = 0; i < k; ++i) {
    if (hull.edge_angle((i + 1) % k) < hull.edge_angle(i)) ++wraps;
  }
  if (k != 0 && wraps != 1) return Fail(error, "hull winds more than once");
  for (int i = 0; i < k; ++i) {
    uint16_t angle = 0;
    in.GetU16(&angle);
    const int difference =
        static_cast<int>(static_cast<uint16_t>(angle - QuantizeAngle(hull.edge_angle(i))));
    if (difference != 0 && difference != 1 && difference != 65535) {
      return Fail(error, "tangent table does not match the hull");
    }
  }
  payload->hull = std::move(hull);
  payload->foreground_pixels = static_cast<int>(pixels);
  return true;
}

}  // namespace silnet

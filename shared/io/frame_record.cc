#include "shared/io/frame_record.h"

#include "shared/util/byte_io.h"

namespace silnet {
namespace {

constexpr uint8_t kVersion = 1;
constexpr uint64_t kMaxIdLength = 255;
constexpr uint64_t kMaxPayload = 16u << 20;

bool Fail(std::string* error, const char* reason) {
  if (error != nullptr) *error = reason;
  return false;
}

}  // namespace

std::vector<uint8_t> SerializeFrameRecord(const FrameRecord& r) {
  std::vector<uint8_t> bytes;
  bytes.reserve(40 + r.camera_id.size() + r.payload.size());
  ByteWriter out(&bytes);
  out.PutU8(kVersion);
  out.PutVarint(r.camera_id.size());
  bytes.insert(bytes.end(), r.camera_id.begin(), r.camera_id.end());
  out.PutU32(r.session);
  out.PutU32(static_cast<uint32_t>(r.frame_index));
  out.PutU32(static_cast<uint32_t>(r.frame_index >> 32));
  const auto time = static_cast<uint64_t>(r.capture_time_ns);
  out.PutU32(static_cast<uint32_t>(time));
  out.PutU32(static_cast<uint32_t>(time >> 32));
  out.PutU16(r.width);
  out.PutU16(r.height);
  out.PutU32(r.flags);
  out.PutVarint(r.payload.size());
  bytes.insert(bytes.end(), r.payload.begin(), r.payload.end());
  return bytes;
}

bool ParseFrameRecord(std::span<const uint8_t> bytes, FrameRecord* record, std::string* error) {
  ByteReader in(bytes);
  uint8_t version = 0;
  if (!in.GetU8(&version) || version != kVersion)
    return Fail(error, "unknown frame record version");
  uint64_t id_length = 0;
  if (!in.GetVarint(&id_length) || id_length > kMaxIdLength || id_length > in.remaining()) {
    return Fail(error, "bad camera id length");
  }
  FrameRecord r;
  r.camera_id.assign(reinterpret_cast<const char*>(bytes.data() + in.position()), id_length);
  ByteReader rest(bytes.subspan(in.position() + id_length));
  uint32_t index_lo = 0, index_hi = 0, time_lo = 0, time_hi = 0;
  uint64_t payload_length = 0;
  if (!rest.GetU32(&r.session) || !rest.GetU32(&index_lo) || !rest.GetU32(&index_hi) ||
      !rest.GetU32(&time_lo) || !rest.GetU32(&time_hi) || !rest.GetU16(&r.width) ||
      !rest.GetU16(&r.height) || !rest.GetU32(&r.flags) || !rest.GetVarint(&payload_length)) {
    return Fail(error, "frame record truncated");
  }
  if (payload_length > kMaxPayload || payload_length != rest.remaining()) {
    return Fail(error, "frame record payload length mismatch");
  }
  r.frame_index = (static_cast<uint64_t>(index_hi) << 32) | index_lo;
  r.capture_time_ns = static_cast<int64_t>((static_cast<uint64_t>(time_hi) << 32) | time_lo);
  const size_t start = bytes.size() - payload_length;
  r.payload.assign(bytes.begin() + static_cast<std::ptrdiff_t>(start), bytes.end());
  *record = std::move(r);
  return true;
}

}  // namespace silnet

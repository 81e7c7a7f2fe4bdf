#pragma once
// One frame of a camera's HullFrame or Contour stream, independent of DDS: what the node
// records with --record, what the aggregator's session store keeps, and what tests compare.
// Serialised form (little-endian): u8 version (1), varint camera id length + bytes,
// u32 session, u64 frame index, u64 capture time (ns, two's complement), u16 width,
// u16 height, u32 flags, varint payload length + payload bytes.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace silnet {

// A per-frame sample of one camera.
struct FrameRecord {
  std::string camera_id;
  uint32_t session = 0;
  uint64_t frame_index = 0;
  int64_t capture_time_ns = 0;
  uint16_t width = 0;
  uint16_t height = 0;
  uint32_t flags = 0;            // silnet_wire_FRAME_* bits
  std::vector<uint8_t> payload;  // hull (HullFrame) or contour (Contour) encoding

  bool operator==(const FrameRecord&) const = default;
};

// Serialises a record.
std::vector<uint8_t> SerializeFrameRecord(const FrameRecord& record);

// Parses a serialised record; false with a reason if the bytes are malformed (never reads
// out of bounds; camera ids over 255 bytes and payloads over 16 MiB are rejected).
bool ParseFrameRecord(std::span<const uint8_t> bytes, FrameRecord* record, std::string* error);

}  // namespace silnet

#pragma once
// The checks a received frame sample passes before anything uses it: a printable camera id,
// a non-zero image size, and a payload that decodes and validates as the sample's kind.

#include <string>

#include "shared/io/frame_record.h"

namespace silnet {

// What a frame sample's payload holds.
enum class FramePayloadKind { kHull, kContour };

// Returns why `record` is malformed as a sample of `kind`, or an empty string if it is
// well formed. Never reads outside the record's payload, whatever its bytes.
std::string FindFrameSampleProblem(const FrameRecord& record, FramePayloadKind kind);

}  // namespace silnet

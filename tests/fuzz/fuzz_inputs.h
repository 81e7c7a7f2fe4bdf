#pragma once
// What silnet's fuzz targets feed untrusted bytes to, and the valid inputs they start from.
// The same functions run under libFuzzer (tests/fuzz/*_fuzzer.cc, scripts/fuzz) and in the
// ordinary test suite over the seeds, deterministic mutations of them and every input kept
// in tests/fuzz/regressions/ (fuzz_regression_test.cc). Each function aborts if an
// invariant of the code under test is broken, so the fuzzer reports logic errors as well as
// crashes and sanitizer findings.

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "shared/io/frame_record.h"

namespace silnet::fuzz {

// A frame sample as it leaves DDS: the fixed fields of a silnet_wire_HullFrame / Contour
// (camera id bytes, session, index, time, size, flags) followed by the payload bytes.
std::vector<uint8_t> PackFrameSample(const FrameRecord& record);

// Unpacks `bytes` into a HullFrame and a Contour wire sample, converts them as the
// aggregator does and runs the aggregator's sample checks; a payload that passes must
// satisfy what the decoders promise (vertices in the image, convex positive hull, ...).
// Returns how many of the two readings were accepted.
int FuzzFrameSample(std::span<const uint8_t> bytes);

// Writes `bytes` to a scratch file and reads it as a session log; the sessions returned
// must be ascending with strictly increasing frame indices and consistent counts.
// Returns the number of frames read (0 if the file was refused).
int FuzzSessionLog(std::span<const uint8_t> bytes);

// The files users hand to silnet's jobs: the first byte picks the reader (even: a
// calibration YAML read as at frame 1000, moves applied; odd: an oriented point-cloud PLY),
// the rest is written to a scratch file and read. What is read must keep the readers'
// promises (cameras with positive focal lengths, rotations, finite fields and distinct ids;
// one normal per point). Returns 1 if the file was read, 0 if it was refused.
int FuzzInputFile(std::span<const uint8_t> bytes);

// Valid inputs for the first two targets: samples of hulls and contours of a few
// silhouettes, and a session log with two sessions, a camera description, a duplicate and a
// torn tail.
std::vector<std::vector<uint8_t>> FrameSampleSeeds();
std::vector<std::vector<uint8_t>> SessionLogSeeds();
// A calibration with a camera move, and a small point cloud, each behind its selector byte.
std::vector<std::vector<uint8_t>> InputFileSeeds();

}  // namespace silnet::fuzz

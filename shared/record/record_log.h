#pragma once
// Crash-safe, append-only, checksummed record logs: the session recordings of the camera
// node (--record) and the aggregator's per-camera session store (DESIGN.md "Files").
//
// On-disk format (version 1). All integers are little-endian; there is no padding.
//
// File header, 64 bytes, at offset 0:
//   offset size field
//        0    8 magic, the ASCII bytes "SILNETLG" (no terminator)
//        8    2 u16 format version, 1
//       10    2 u16 header size in bytes, 64
//       12    4 reserved, written as zero, ignored by readers
//       16   32 stream kind: the caller's 1..32-byte string (no NUL inside), NUL-padded
//       48    8 i64 creation time, nanoseconds since 1970-01-01T00:00:00Z
//       56    4 reserved, written as zero, ignored by readers
//       60    4 u32 CRC-32 of bytes 0..59
// Records follow back to back from offset 64. Record = 16-byte header + payload:
//   offset size field
//        0    4 u32 record magic 0xEC524C53 (bytes 53 4C 52 EC: "SLR" then 0xEC)
//        4    4 u32 payload length n, at most kMaxPayloadBytes (64 MiB); larger is corruption
//        8    2 u16 record type (the caller's)
//       10    2 u16 flags (the caller's)
//       12    4 u32 CRC-32 of header bytes 4..11 (length, type, flags) followed by the payload
//       16    n payload
// CRC-32 is zlib's crc32() (ISO-HDLC / IEEE 802.3 polynomial, initial value 0).
//
// Crash safety and durability. The writer issues one positioned write per record, straight
// into the kernel (no user-space buffer), so:
//   * a record whose Append() returned ok survives a crash of the writing process and is
//     visible at once to readers in other processes;
//   * a record survives an OS crash or power loss once a later Flush() (fdatasync) or
//     Close() has returned ok; unflushed records may be lost, and the last one may be torn;
//   * a failed Append() (ENOSPC, EFBIG, EIO, ...) cuts the file back to the previous record
//     boundary, so the caller keeps the data and retries later;
//   * reopening for writing truncates a torn tail (an incomplete or damaged last record or
//     garbage after the last good record) and continues from a clean boundary. Damage with
//     valid records after it is never truncated: Open() refuses and the file can be salvaged
//     with a resynchronising reader.
// Readers never return a record whose checksum does not match. A reader may follow a file
// another process is appending to: it stops at the last complete record (kEnd or
// kTornTail) and a later Next() continues once more data has arrived.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace silnet {

// Largest payload of one record; longer length fields are treated as corruption.
inline constexpr uint32_t kMaxRecordPayloadBytes = 64u << 20;
// Longest stream kind stored in the file header.
inline constexpr std::size_t kMaxStreamKindBytes = 32;
// Size of the file header and of a record header in bytes.
inline constexpr std::size_t kRecordLogFileHeaderBytes = 64;
inline constexpr std::size_t kRecordHeaderBytes = 16;

// Outcome of a record-log operation: ok, or a readable reason naming the file and, for OS
// failures, the errno value (0 when the failure is not an OS error, e.g. a foreign file).
class [[nodiscard]] RecordLogStatus {
 public:
  // Success.
  static RecordLogStatus Ok() { return RecordLogStatus(); }
  // Failure with `message` and the errno value that caused it (0 if none).
  static RecordLogStatus Error(std::string message, int error_number = 0);

  bool ok() const { return !failed_; }
  // Empty when ok.
  const std::string& message() const { return message_; }
  int error_number() const { return error_number_; }

 private:
  bool failed_ = false;
  int error_number_ = 0;
  std::string message_;
};

// The decoded file header.
struct RecordLogHeader {
  uint16_t version = 0;
  std::string stream_kind;
  std::chrono::system_clock::time_point created;
};

// One record as read back: its header fields, payload and position in the file.
struct Record {
  // Byte offset of the record header from the start of the file.
  uint64_t offset = 0;
  uint16_t type = 0;
  uint16_t flags = 0;
  std::vector<uint8_t> payload;
};

// What RecordLogWriter::Open() found and repaired.
struct RecordLogRecovery {
  // The file was created, or held only an empty or torn file header and was initialised.
  bool initialised = false;
  // Complete, valid records in the file after recovery.
  uint64_t records = 0;
  // Bytes removed after the last valid record (a torn tail), and whether any were.
  uint64_t bytes_truncated = 0;
  bool tail_truncated = false;
  // Why the tail was cut (empty if it was not).
  std::string tail_reason;
};

// Appends records to one log file. Only one writer may have a file open at a time (an
// exclusive flock, across processes); readers need no lock. Not thread-safe.
class RecordLogWriter {
 public:
  // A writer with no file open.
  RecordLogWriter() = default;
  // Closes the file (as Close(), logging a warning if that fails).
  ~RecordLogWriter();
  RecordLogWriter(RecordLogWriter&& other) noexcept;
  RecordLogWriter& operator=(RecordLogWriter&& other) noexcept;
  RecordLogWriter(const RecordLogWriter&) = delete;
  RecordLogWriter& operator=(const RecordLogWriter&) = delete;

  // Creates `path` with a header of `stream_kind`, or reopens an existing log of that
  // stream kind, checking every record (time proportional to the file size) and truncating
  // a torn tail so appends continue at a record boundary (see recovery()). Refuses, without
  // changing the file, a foreign file, another stream kind, a newer format version, a damaged
  // header, damage followed by valid records, and a file another writer holds. Throws CheckError if
  // this writer is already open or if `stream_kind` is empty, longer than kMaxStreamKindBytes or
  // contains a NUL.
  RecordLogStatus Open(const std::filesystem::path& path, std::string_view stream_kind);

  // Appends one record with a single write. On failure the file is cut back to the previous
  // record boundary (or, if even that fails, the next Append() cuts it first) and the
  // status carries the errno; the writer stays usable. Throws CheckError if no file is
  // open or `payload` is longer than kMaxRecordPayloadBytes.
  RecordLogStatus Append(uint16_t type, std::span<const uint8_t> payload, uint16_t flags = 0);

  // Makes every appended record durable (fdatasync). Throws CheckError if no file is open.
  RecordLogStatus Flush();

  // Flushes and closes; the writer is closed afterwards even if the flush failed. Closing a
  // closed writer is ok.
  RecordLogStatus Close();

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }
  // The header of the open file.
  const RecordLogHeader& header() const { return header_; }
  // What Open() found and repaired.
  const RecordLogRecovery& recovery() const { return recovery_; }
  // Records in the file (recovered plus appended).
  uint64_t records() const { return records_; }
  // File size at the last record boundary, where the next record goes.
  uint64_t end_offset() const { return end_; }

 private:
  int fd_ = -1;
  std::filesystem::path path_;
  RecordLogHeader header_;
  RecordLogRecovery recovery_;
  uint64_t records_ = 0;
  uint64_t end_ = 0;
  // A failed Append() could not cut its partial record; the next Append() must.
  bool needs_truncate_ = false;
};

// How Next() ended.
enum class ReadStatus {
  // A valid record was returned.
  kOk,
  // The file ends at a record boundary (a follower may call Next() again later).
  kEnd,
  // The file ends inside a record (a crash, or a writer still writing it) and no valid
  // record follows. The position stays; a later Next() continues if the record completes.
  kTornTail,
  // Bytes at problem_offset() are not a valid record (bad magic, length or checksum), or an
  // incomplete record is followed by valid ones. Without resync the position stays.
  kCorrupt,
  // The file could not be read (problem() holds the errno message); a retry may succeed.
  kIoError,
};

// Name of a ReadStatus ("ok", "end", "torn tail", "corrupt", "i/o error").
const char* ToString(ReadStatus status);

// Options of a RecordLogReader.
struct RecordLogReaderOptions {
  // If not empty, Open() refuses a file of another stream kind.
  std::string expected_stream_kind;
  // Salvage mode: after damage, scan forward to the next valid record, count the skipped
  // bytes and go on instead of reporting kCorrupt. A record embedded in a damaged payload
  // may then be returned if its own checksum holds.
  bool resync = false;
};

// Counters of a RecordLogReader.
struct RecordLogReaderStats {
  uint64_t records = 0;
  // Resync mode: bytes skipped over damaged regions, and how many such regions.
  uint64_t bytes_skipped = 0;
  uint64_t corrupt_regions = 0;
};

// Reads records in file order. Robust to arbitrary file contents: reads are bounds-checked
// against the file size and a payload buffer is allocated only for a length that fits in
// the file and in kMaxRecordPayloadBytes. Finding out whether valid records follow damage
// scans the rest of the file. Not thread-safe.
class RecordLogReader {
 public:
  // A reader with no file open.
  RecordLogReader() = default;
  ~RecordLogReader();
  RecordLogReader(RecordLogReader&& other) noexcept;
  RecordLogReader& operator=(RecordLogReader&& other) noexcept;
  RecordLogReader(const RecordLogReader&) = delete;
  RecordLogReader& operator=(const RecordLogReader&) = delete;

  // Opens `path` and validates its header; an error names the problem (foreign file,
  // incomplete or damaged header, newer version, other stream kind). A file a writer is
  // creating at this very moment may be refused as incomplete; opening again later works. Throws
  // CheckError if this reader is already open.
  RecordLogStatus Open(const std::filesystem::path& path, RecordLogReaderOptions options = {});

  // Reads the next record into `record` (on kOk only; otherwise `record` is cleared).
  // Throws CheckError if no file is open or `record` is null.
  ReadStatus Next(Record* record);

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }
  const RecordLogHeader& header() const { return header_; }
  // Offset of the next record to read.
  uint64_t offset() const { return offset_; }
  // Where and why the last Next() did not return a record (0 and empty after kOk or kEnd).
  uint64_t problem_offset() const { return problem_offset_; }
  const std::string& problem() const { return problem_; }
  const RecordLogReaderStats& stats() const { return stats_; }

 private:
  ReadStatus Report(ReadStatus status, uint64_t offset, std::string problem, Record* record);

  int fd_ = -1;
  std::filesystem::path path_;
  RecordLogReaderOptions options_;
  RecordLogHeader header_;
  uint64_t offset_ = 0;
  uint64_t problem_offset_ = 0;
  std::string problem_;
  RecordLogReaderStats stats_;
  std::vector<uint8_t> scratch_;
};

}  // namespace silnet

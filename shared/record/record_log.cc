#include "shared/record/record_log.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <optional>
#include <system_error>
#include <utility>

#include "shared/util/check.h"
#include "shared/util/crc32.h"
#include "shared/util/log.h"

namespace silnet {
namespace {

constexpr std::array<uint8_t, 8> kFileMagic = {'S', 'I', 'L', 'N', 'E', 'T', 'L', 'G'};
constexpr uint16_t kFormatVersion = 1;
constexpr std::array<uint8_t, 4> kRecordMagicBytes = {0x53, 0x4C, 0x52, 0xEC};  // 0xEC524C53
constexpr std::size_t kScanChunkBytes = std::size_t{1} << 20;
constexpr std::size_t kCrcChunkBytes = std::size_t{64} << 10;

// File header layout (see record_log.h).
constexpr std::size_t kVersionAt = 8;
constexpr std::size_t kHeaderSizeAt = 10;
constexpr std::size_t kStreamKindAt = 16;
constexpr std::size_t kCreatedAt = 48;
constexpr std::size_t kHeaderCrcAt = 60;

void PutU16(uint8_t* out, uint16_t value) {
  out[0] = static_cast<uint8_t>(value);
  out[1] = static_cast<uint8_t>(value >> 8);
}

void PutU32(uint8_t* out, uint32_t value) {
  for (int i = 0; i < 4; ++i)
    out[i] = static_cast<uint8_t>(value >> (8 * i));
}

void PutU64(uint8_t* out, uint64_t value) {
  for (int i = 0; i < 8; ++i)
    out[i] = static_cast<uint8_t>(value >> (8 * i));
}

uint16_t GetU16(const uint8_t* in) {
  return static_cast<uint16_t>(in[0] | (in[1] << 8));
}

uint32_t GetU32(const uint8_t* in) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i)
    value = (value << 8) | in[i];
  return value;
}

uint64_t GetU64(const uint8_t* in) {
  uint64_t value = 0;
  for (int i = 7; i >= 0; --i)
    value = (value << 8) | in[i];
  return value;
}

std::string ErrnoText(int error_number) {
  return std::generic_category().message(error_number);
}

RecordLogStatus ErrnoStatus(const std::string& what, int error_number) {
  return RecordLogStatus::Error(what + ": " + ErrnoText(error_number), error_number);
}

// Owns a file descriptor until released.
class UniqueFd {
 public:
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() {
    if (fd_ >= 0) ::close(fd_);
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;

  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

// Reads up to `size` bytes at `offset`; returns the count (less only at the end of the file)
// or -1 with errno set.
ssize_t ReadAt(int fd, uint64_t offset, uint8_t* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pread(fd, data + done, size - done, static_cast<off_t>(offset + done));
    if (n < 0) {
      if (errno == EINTR) continue;
      return -1;
    }
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  return static_cast<ssize_t>(done);
}

// Writes all of `parts` at `offset`; returns 0 or the errno of the failure (the file may
// then hold part of the data).
int WriteAllAt(int fd, uint64_t offset, iovec* parts, int count) {
  while (count > 0) {
    const ssize_t n = ::pwritev(fd, parts, count, static_cast<off_t>(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    offset += static_cast<uint64_t>(n);
    std::size_t left = static_cast<std::size_t>(n);
    while (count > 0 && left >= parts->iov_len) {
      left -= parts->iov_len;
      ++parts;
      --count;
    }
    if (count > 0) {
      parts->iov_base = static_cast<uint8_t*>(parts->iov_base) + left;
      parts->iov_len -= left;
    }
  }
  return 0;
}

// Current size of the open file, or the errno of the failure.
int FileSize(int fd, uint64_t* size) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return errno;
  *size = static_cast<uint64_t>(st.st_size);
  return 0;
}

// Makes the creation of `path` durable; file systems without directory fsync are ignored.
int SyncParentDir(const std::filesystem::path& path) {
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return errno;
  const int result = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return result == EINVAL ? 0 : result;
}

void CheckStreamKind(std::string_view stream_kind) {
  SILNET_CHECK_MSG(!stream_kind.empty() && stream_kind.size() <= kMaxStreamKindBytes &&
                       stream_kind.find('\0') == std::string_view::npos,
                   "a record log stream kind must be 1.."
                       << kMaxStreamKindBytes << " bytes without NUL, not '" << stream_kind << "'");
}

std::array<uint8_t, kRecordLogFileHeaderBytes> EncodeFileHeader(const RecordLogHeader& header) {
  std::array<uint8_t, kRecordLogFileHeaderBytes> bytes{};
  std::copy(kFileMagic.begin(), kFileMagic.end(), bytes.begin());
  PutU16(bytes.data() + kVersionAt, header.version);
  PutU16(bytes.data() + kHeaderSizeAt, static_cast<uint16_t>(kRecordLogFileHeaderBytes));
  std::copy(header.stream_kind.begin(), header.stream_kind.end(), bytes.begin() + kStreamKindAt);
  const auto nanoseconds =
      std::chrono::duration_cast<std::chrono::nanoseconds>(header.created.time_since_epoch());
  PutU64(bytes.data() + kCreatedAt, static_cast<uint64_t>(nanoseconds.count()));
  PutU32(bytes.data() + kHeaderCrcAt, Crc32(0, bytes.data(), kHeaderCrcAt));
  return bytes;
}

enum class HeaderCheck { kOk, kIncomplete, kRefused };

// Decodes the first `size` bytes of a file (at most a header's worth). kIncomplete means a
// prefix of a header: fewer than 64 bytes starting with (a prefix of) the magic.
HeaderCheck DecodeFileHeader(const uint8_t* bytes, std::size_t size, RecordLogHeader* header,
                             std::string* why) {
  if (std::memcmp(bytes, kFileMagic.data(), std::min(size, kFileMagic.size())) != 0) {
    *why = "not a silnet record log (it does not start with \"SILNETLG\")";
    return HeaderCheck::kRefused;
  }
  if (size < kRecordLogFileHeaderBytes) {
    *why = fmt::format("incomplete record log header ({} of {} bytes)", size,
                       kRecordLogFileHeaderBytes);
    return HeaderCheck::kIncomplete;
  }
  const uint32_t stored = GetU32(bytes + kHeaderCrcAt);
  const uint32_t computed = Crc32(0, bytes, kHeaderCrcAt);
  if (stored != computed) {
    *why = fmt::format("damaged record log header (checksum {:#010x}, expected {:#010x})", computed,
                       stored);
    return HeaderCheck::kRefused;
  }
  const uint16_t version = GetU16(bytes + kVersionAt);
  if (version != kFormatVersion) {
    *why = fmt::format("record log format version {} is not supported (this program reads {})",
                       version, kFormatVersion);
    return HeaderCheck::kRefused;
  }
  const uint16_t header_size = GetU16(bytes + kHeaderSizeAt);
  if (header_size != kRecordLogFileHeaderBytes) {
    *why =
        fmt::format("record log header size {} is not {}", header_size, kRecordLogFileHeaderBytes);
    return HeaderCheck::kRefused;
  }
  const uint8_t* kind = bytes + kStreamKindAt;
  const std::size_t kind_size =
      static_cast<std::size_t>(std::find(kind, kind + kMaxStreamKindBytes, uint8_t{0}) - kind);
  const bool padded = std::all_of(kind + kind_size, kind + kMaxStreamKindBytes,
                                  [](uint8_t byte) { return byte == 0; });
  if (kind_size == 0 || !padded) {
    *why = "record log header holds no valid stream kind";
    return HeaderCheck::kRefused;
  }
  header->version = version;
  header->stream_kind.assign(reinterpret_cast<const char*>(kind), kind_size);
  const auto nanoseconds =
      std::chrono::nanoseconds(static_cast<int64_t>(GetU64(bytes + kCreatedAt)));
  header->created = std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(nanoseconds));
  return HeaderCheck::kOk;
}

std::array<uint8_t, kRecordHeaderBytes> EncodeRecordHeader(uint16_t type, uint16_t flags,
                                                           std::span<const uint8_t> payload) {
  std::array<uint8_t, kRecordHeaderBytes> bytes{};
  std::copy(kRecordMagicBytes.begin(), kRecordMagicBytes.end(), bytes.begin());
  PutU32(bytes.data() + 4, static_cast<uint32_t>(payload.size()));
  PutU16(bytes.data() + 8, type);
  PutU16(bytes.data() + 10, flags);
  const uint32_t crc = Crc32(Crc32(0, bytes.data() + 4, 8), payload.data(), payload.size());
  PutU32(bytes.data() + 12, crc);
  return bytes;
}

enum class ProbeKind { kValid, kIncomplete, kBad, kIoError };

// What a record boundary holds.
struct Probe {
  ProbeKind kind = ProbeKind::kBad;
  uint32_t length = 0;
  uint16_t type = 0;
  uint16_t flags = 0;
  std::string why;
  int error_number = 0;
};

Probe BadProbe(ProbeKind kind, std::string why, int error_number = 0) {
  Probe probe;
  probe.kind = kind;
  probe.why = std::move(why);
  probe.error_number = error_number;
  return probe;
}

// Examines the record at `offset` (< `size`, the file size). With `payload`, a valid
// record's payload is read into it; otherwise the checksum is computed in chunks through
// `scratch`. Nothing beyond `size` is read and nothing larger than the record is allocated.
Probe ProbeRecord(int fd, uint64_t offset, uint64_t size, std::vector<uint8_t>* payload,
                  std::vector<uint8_t>* scratch) {
  std::array<uint8_t, kRecordHeaderBytes> head{};
  const ssize_t got =
      ReadAt(fd, offset, head.data(),
             static_cast<std::size_t>(std::min<uint64_t>(head.size(), size - offset)));
  if (got < 0) return BadProbe(ProbeKind::kIoError, ErrnoText(errno), errno);
  const std::size_t have = static_cast<std::size_t>(got);
  if (std::memcmp(head.data(), kRecordMagicBytes.data(),
                  std::min(have, kRecordMagicBytes.size())) != 0) {
    return BadProbe(ProbeKind::kBad, "bad record magic");
  }
  Probe probe;
  if (have >= 8) {
    probe.length = GetU32(head.data() + 4);
    if (probe.length > kMaxRecordPayloadBytes) {
      return BadProbe(ProbeKind::kBad, fmt::format("payload length {} exceeds the limit of {}",
                                                   probe.length, kMaxRecordPayloadBytes));
    }
  }
  if (have < head.size()) {
    return BadProbe(ProbeKind::kIncomplete,
                    fmt::format("incomplete record header ({} of {} bytes)", have, head.size()));
  }
  probe.type = GetU16(head.data() + 8);
  probe.flags = GetU16(head.data() + 10);
  const uint32_t stored = GetU32(head.data() + 12);
  const uint64_t available = size - offset - head.size();
  if (probe.length > available) {
    return BadProbe(
        ProbeKind::kIncomplete,
        fmt::format("incomplete record ({} of {} payload bytes)", available, probe.length));
  }
  uint32_t crc = Crc32(0, head.data() + 4, 8);
  const uint64_t payload_at = offset + head.size();
  if (payload != nullptr) {
    payload->resize(probe.length);
    const ssize_t n = ReadAt(fd, payload_at, payload->data(), probe.length);
    if (n < 0) return BadProbe(ProbeKind::kIoError, ErrnoText(errno), errno);
    if (static_cast<std::size_t>(n) < probe.length) {
      return BadProbe(ProbeKind::kIncomplete, "the file shrank while the record was read");
    }
    crc = Crc32(crc, payload->data(), probe.length);
  } else {
    scratch->resize(std::min<std::size_t>(kCrcChunkBytes, std::max<uint32_t>(probe.length, 1)));
    uint64_t done = 0;
    while (done < probe.length) {
      const std::size_t part = std::min<std::size_t>(scratch->size(), probe.length - done);
      const ssize_t n = ReadAt(fd, payload_at + done, scratch->data(), part);
      if (n < 0) return BadProbe(ProbeKind::kIoError, ErrnoText(errno), errno);
      if (static_cast<std::size_t>(n) < part) {
        return BadProbe(ProbeKind::kIncomplete, "the file shrank while the record was read");
      }
      crc = Crc32(crc, scratch->data(), part);
      done += part;
    }
  }
  if (crc != stored) {
    return BadProbe(
        ProbeKind::kBad,
        fmt::format("checksum mismatch (computed {:#010x}, stored {:#010x})", crc, stored));
  }
  probe.kind = ProbeKind::kValid;
  return probe;
}

// The first offset in [from, size) holding a complete, valid record, if any.
struct Scan {
  std::optional<uint64_t> found;
  int error_number = 0;
};

Scan FindValidRecord(int fd, uint64_t from, uint64_t size, std::vector<uint8_t>* scratch) {
  Scan scan;
  if (from >= size || size - from < kRecordHeaderBytes) return scan;
  std::vector<uint8_t> chunk(
      static_cast<std::size_t>(std::min<uint64_t>(kScanChunkBytes, size - from)));
  uint64_t pos = from;
  while (size - pos >= kRecordHeaderBytes) {
    const std::size_t want = static_cast<std::size_t>(std::min<uint64_t>(chunk.size(), size - pos));
    const ssize_t got = ReadAt(fd, pos, chunk.data(), want);
    if (got < 0) {
      scan.error_number = errno;
      return scan;
    }
    const std::size_t have = static_cast<std::size_t>(got);
    if (have < kRecordMagicBytes.size()) return scan;
    for (std::size_t i = 0; i + kRecordMagicBytes.size() <= have; ++i) {
      if (chunk[i] != kRecordMagicBytes[0] ||
          std::memcmp(chunk.data() + i, kRecordMagicBytes.data(), kRecordMagicBytes.size()) != 0) {
        continue;
      }
      const uint64_t candidate = pos + i;
      if (size - candidate < kRecordHeaderBytes) return scan;
      const Probe probe = ProbeRecord(fd, candidate, size, nullptr, scratch);
      if (probe.kind == ProbeKind::kIoError) {
        scan.error_number = probe.error_number;
        return scan;
      }
      if (probe.kind == ProbeKind::kValid) {
        scan.found = candidate;
        return scan;
      }
    }
    if (have < want) return scan;
    pos += have - (kRecordMagicBytes.size() - 1);
  }
  return scan;
}

// Closes `writer`, logging instead of reporting a failure (destructors and moves).
void CloseOrWarn(RecordLogWriter& writer) {
  const RecordLogStatus status = writer.Close();
  if (!status.ok()) spdlog::warn("{}", status.message());
}

}  // namespace

RecordLogStatus RecordLogStatus::Error(std::string message, int error_number) {
  RecordLogStatus status;
  status.failed_ = true;
  status.error_number_ = error_number;
  status.message_ = std::move(message);
  return status;
}

const char* ToString(ReadStatus status) {
  switch (status) {
    case ReadStatus::kOk:
      return "ok";
    case ReadStatus::kEnd:
      return "end";
    case ReadStatus::kTornTail:
      return "torn tail";
    case ReadStatus::kCorrupt:
      return "corrupt";
    case ReadStatus::kIoError:
      return "i/o error";
  }
  return "unknown";
}

// ---------------------------------------------------------------------------------------
// RecordLogWriter

RecordLogWriter::~RecordLogWriter() {
  CloseOrWarn(*this);
}

RecordLogWriter::RecordLogWriter(RecordLogWriter&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      path_(std::move(other.path_)),
      header_(std::move(other.header_)),
      recovery_(std::move(other.recovery_)),
      records_(other.records_),
      end_(other.end_),
      needs_truncate_(other.needs_truncate_) {}

RecordLogWriter& RecordLogWriter::operator=(RecordLogWriter&& other) noexcept {
  if (this != &other) {
    CloseOrWarn(*this);
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    header_ = std::move(other.header_);
    recovery_ = std::move(other.recovery_);
    records_ = other.records_;
    end_ = other.end_;
    needs_truncate_ = other.needs_truncate_;
  }
  return *this;
}

RecordLogStatus RecordLogWriter::Open(const std::filesystem::path& path,
                                      std::string_view stream_kind) {
  SILNET_CHECK_MSG(!is_open(), "record log writer already has " << path_ << " open");
  CheckStreamKind(stream_kind);
  const std::string name = path.string();

  bool created = false;
  int raw = ::open(name.c_str(), O_RDWR | O_CLOEXEC);
  if (raw < 0 && errno == ENOENT) {
    raw = ::open(name.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (raw >= 0) {
      created = true;
    } else if (errno == EEXIST) {
      raw = ::open(name.c_str(), O_RDWR | O_CLOEXEC);
    }
  }
  if (raw < 0) return ErrnoStatus("cannot open record log " + name + " for writing", errno);
  UniqueFd fd(raw);
  if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) {
    const int error_number = errno;
    if (error_number == EWOULDBLOCK) {
      return RecordLogStatus::Error(
          "record log " + name + " is already open for writing by another writer", error_number);
    }
    return ErrnoStatus("cannot lock record log " + name, error_number);
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return ErrnoStatus("cannot stat record log " + name, errno);
  if (!S_ISREG(st.st_mode)) {
    return RecordLogStatus::Error("record log " + name + " is not a regular file");
  }
  uint64_t size = static_cast<uint64_t>(st.st_size);

  std::array<uint8_t, kRecordLogFileHeaderBytes> bytes{};
  const ssize_t got = ReadAt(fd.get(), 0, bytes.data(),
                             static_cast<std::size_t>(std::min<uint64_t>(bytes.size(), size)));
  if (got < 0) return ErrnoStatus("cannot read record log " + name, errno);

  RecordLogHeader header;
  RecordLogRecovery recovery;
  std::string why;
  const HeaderCheck check =
      DecodeFileHeader(bytes.data(), static_cast<std::size_t>(got), &header, &why);
  if (check == HeaderCheck::kRefused) {
    return RecordLogStatus::Error("cannot append to " + name + ": " + why);
  }
  uint64_t end = kRecordLogFileHeaderBytes;
  if (check == HeaderCheck::kIncomplete) {
    // A new file, an empty one, or a crash while a header was written: no records to lose.
    header.version = kFormatVersion;
    header.stream_kind = std::string(stream_kind);
    header.created = std::chrono::system_clock::now();
    bytes = EncodeFileHeader(header);
    iovec part{bytes.data(), bytes.size()};
    const int error_number = WriteAllAt(fd.get(), 0, &part, 1);
    if (error_number != 0) {
      return ErrnoStatus("cannot write the header of record log " + name, error_number);
    }
    if (::fdatasync(fd.get()) != 0) return ErrnoStatus("cannot sync record log " + name, errno);
    if (created) {
      const int dir_error = SyncParentDir(path);
      if (dir_error != 0) {
        return ErrnoStatus("cannot sync the folder of record log " + name, dir_error);
      }
    }
    recovery.initialised = true;
  } else {
    if (header.stream_kind != stream_kind) {
      return RecordLogStatus::Error(
          fmt::format("cannot append to {}: it records stream kind '{}', not '{}'", name,
                      header.stream_kind, stream_kind));
    }
    std::vector<uint8_t> scratch;
    while (end < size) {
      const Probe probe = ProbeRecord(fd.get(), end, size, nullptr, &scratch);
      if (probe.kind == ProbeKind::kValid) {
        ++recovery.records;
        end += kRecordHeaderBytes + probe.length;
        continue;
      }
      if (probe.kind == ProbeKind::kIoError) {
        return ErrnoStatus(fmt::format("cannot read record log {} at offset {}", name, end),
                           probe.error_number);
      }
      const Scan scan = FindValidRecord(fd.get(), end + 1, size, &scratch);
      if (scan.error_number != 0) {
        return ErrnoStatus("cannot read record log " + name, scan.error_number);
      }
      if (scan.found) {
        return RecordLogStatus::Error(fmt::format(
            "cannot append to {}: damaged record at offset {} ({}) is followed by a valid "
            "record at offset {}; salvage the file with a resynchronising reader",
            name, end, probe.why, *scan.found));
      }
      if (::ftruncate(fd.get(), static_cast<off_t>(end)) != 0) {
        return ErrnoStatus(fmt::format("cannot cut the torn tail of {} at offset {}", name, end),
                           errno);
      }
      if (::fdatasync(fd.get()) != 0) return ErrnoStatus("cannot sync record log " + name, errno);
      recovery.tail_truncated = true;
      recovery.bytes_truncated = size - end;
      recovery.tail_reason = probe.why;
      spdlog::warn("record log {}: cut a torn tail of {} bytes at offset {} ({})", name, size - end,
                   end, probe.why);
      size = end;
    }
  }

  fd_ = fd.release();
  path_ = path;
  header_ = std::move(header);
  recovery_ = std::move(recovery);
  records_ = recovery_.records;
  end_ = end;
  needs_truncate_ = false;
  return RecordLogStatus::Ok();
}

RecordLogStatus RecordLogWriter::Append(uint16_t type, std::span<const uint8_t> payload,
                                        uint16_t flags) {
  SILNET_CHECK_MSG(is_open(), "RecordLogWriter::Append without an open file");
  SILNET_CHECK_MSG(payload.size() <= kMaxRecordPayloadBytes,
                   "record payload of " << payload.size() << " bytes exceeds the limit of "
                                        << kMaxRecordPayloadBytes);
  if (needs_truncate_) {
    if (::ftruncate(fd_, static_cast<off_t>(end_)) != 0) {
      return ErrnoStatus("cannot cut a partial record from record log " + path_.string(), errno);
    }
    needs_truncate_ = false;
  }
  std::array<uint8_t, kRecordHeaderBytes> head = EncodeRecordHeader(type, flags, payload);
  std::array<iovec, 2> parts = {iovec{head.data(), head.size()},
                                iovec{const_cast<uint8_t*>(payload.data()), payload.size()}};
  const int error_number = WriteAllAt(fd_, end_, parts.data(), payload.empty() ? 1 : 2);
  if (error_number != 0) {
    if (::ftruncate(fd_, static_cast<off_t>(end_)) != 0) needs_truncate_ = true;
    return ErrnoStatus(
        fmt::format("cannot append a record of {} bytes to {}", payload.size(), path_.string()),
        error_number);
  }
  end_ += kRecordHeaderBytes + payload.size();
  ++records_;
  return RecordLogStatus::Ok();
}

RecordLogStatus RecordLogWriter::Flush() {
  SILNET_CHECK_MSG(is_open(), "RecordLogWriter::Flush without an open file");
  if (::fdatasync(fd_) != 0) return ErrnoStatus("cannot sync record log " + path_.string(), errno);
  return RecordLogStatus::Ok();
}

RecordLogStatus RecordLogWriter::Close() {
  if (!is_open()) return RecordLogStatus::Ok();
  if (needs_truncate_ && ::ftruncate(fd_, static_cast<off_t>(end_)) == 0) needs_truncate_ = false;
  RecordLogStatus status = Flush();
  if (status.ok() && needs_truncate_) {
    status = RecordLogStatus::Error(
        "record log " + path_.string() + " still ends in a partial record (truncation failed)",
        EIO);
  }
  if (::close(std::exchange(fd_, -1)) != 0 && status.ok()) {
    status = ErrnoStatus("cannot close record log " + path_.string(), errno);
  }
  return status;
}

// ---------------------------------------------------------------------------------------
// RecordLogReader

RecordLogReader::~RecordLogReader() {
  if (fd_ >= 0) ::close(fd_);
}

RecordLogReader::RecordLogReader(RecordLogReader&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      path_(std::move(other.path_)),
      options_(std::move(other.options_)),
      header_(std::move(other.header_)),
      offset_(other.offset_),
      problem_offset_(other.problem_offset_),
      problem_(std::move(other.problem_)),
      stats_(other.stats_),
      scratch_(std::move(other.scratch_)) {}

RecordLogReader& RecordLogReader::operator=(RecordLogReader&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    options_ = std::move(other.options_);
    header_ = std::move(other.header_);
    offset_ = other.offset_;
    problem_offset_ = other.problem_offset_;
    problem_ = std::move(other.problem_);
    stats_ = other.stats_;
    scratch_ = std::move(other.scratch_);
  }
  return *this;
}

RecordLogStatus RecordLogReader::Open(const std::filesystem::path& path,
                                      RecordLogReaderOptions options) {
  SILNET_CHECK_MSG(!is_open(), "record log reader already has " << path_ << " open");
  const std::string name = path.string();
  const int raw = ::open(name.c_str(), O_RDONLY | O_CLOEXEC);
  if (raw < 0) return ErrnoStatus("cannot open record log " + name, errno);
  UniqueFd fd(raw);
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return ErrnoStatus("cannot stat record log " + name, errno);
  if (!S_ISREG(st.st_mode)) {
    return RecordLogStatus::Error("record log " + name + " is not a regular file");
  }
  std::array<uint8_t, kRecordLogFileHeaderBytes> bytes{};
  const ssize_t got =
      ReadAt(fd.get(), 0, bytes.data(),
             static_cast<std::size_t>(std::min<uint64_t>(bytes.size(), st.st_size)));
  if (got < 0) return ErrnoStatus("cannot read record log " + name, errno);
  RecordLogHeader header;
  std::string why;
  if (DecodeFileHeader(bytes.data(), static_cast<std::size_t>(got), &header, &why) !=
      HeaderCheck::kOk) {
    return RecordLogStatus::Error("cannot read " + name + ": " + why);
  }
  if (!options.expected_stream_kind.empty() && header.stream_kind != options.expected_stream_kind) {
    return RecordLogStatus::Error(
        fmt::format("cannot read {}: it records stream kind '{}', not '{}'", name,
                    header.stream_kind, options.expected_stream_kind));
  }
  fd_ = fd.release();
  path_ = path;
  options_ = std::move(options);
  header_ = std::move(header);
  offset_ = kRecordLogFileHeaderBytes;
  problem_offset_ = 0;
  problem_.clear();
  stats_ = {};
  return RecordLogStatus::Ok();
}

ReadStatus RecordLogReader::Report(ReadStatus status, uint64_t offset, std::string problem,
                                   Record* record) {
  *record = Record();
  problem_offset_ = offset;
  problem_ = std::move(problem);
  return status;
}

ReadStatus RecordLogReader::Next(Record* record) {
  SILNET_CHECK_MSG(is_open(), "RecordLogReader::Next without an open file");
  SILNET_CHECK(record != nullptr);
  uint64_t size = 0;
  const int stat_error = FileSize(fd_, &size);
  if (stat_error != 0) {
    return Report(ReadStatus::kIoError, offset_, "cannot stat: " + ErrnoText(stat_error), record);
  }
  for (;;) {
    if (offset_ == size) return Report(ReadStatus::kEnd, 0, "", record);
    if (offset_ > size) {
      return Report(ReadStatus::kCorrupt, offset_,
                    fmt::format("the file shrank to {} bytes, before the read position", size),
                    record);
    }
    const Probe probe = ProbeRecord(fd_, offset_, size, &record->payload, &scratch_);
    if (probe.kind == ProbeKind::kValid) {
      record->offset = offset_;
      record->type = probe.type;
      record->flags = probe.flags;
      offset_ += kRecordHeaderBytes + probe.length;
      ++stats_.records;
      problem_offset_ = 0;
      problem_.clear();
      return ReadStatus::kOk;
    }
    if (probe.kind == ProbeKind::kIoError) {
      return Report(ReadStatus::kIoError, offset_, "cannot read: " + probe.why, record);
    }
    const Scan scan = FindValidRecord(fd_, offset_ + 1, size, &scratch_);
    if (scan.error_number != 0) {
      return Report(ReadStatus::kIoError, offset_, "cannot read: " + ErrnoText(scan.error_number),
                    record);
    }
    if (!scan.found) {
      return Report(
          probe.kind == ProbeKind::kIncomplete ? ReadStatus::kTornTail : ReadStatus::kCorrupt,
          offset_, probe.why, record);
    }
    if (!options_.resync) {
      return Report(ReadStatus::kCorrupt, offset_,
                    fmt::format("{}; a valid record follows at offset {}", probe.why, *scan.found),
                    record);
    }
    stats_.bytes_skipped += *scan.found - offset_;
    ++stats_.corrupt_regions;
    offset_ = *scan.found;
  }
}

}  // namespace silnet

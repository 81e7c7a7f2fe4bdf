// Tests of the crash-safe record log: format, round trips, torn tails, corruption,
// resynchronisation, refusals, allocation bounds, failing writes and a reader following a
// writer in another process.

#include "shared/record/record_log.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <new>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

// Records the largest single allocation while armed, to prove that hostile length fields do
// not turn into allocations.
namespace {
std::atomic<bool> g_track_allocations{false};
std::atomic<std::size_t> g_largest_allocation{0};

// malloc and free are reached through function pointers the optimiser cannot see through,
// so GCC does not pair them with operator new and delete and warn about a mismatch.
void* (*volatile g_allocate)(std::size_t) = std::malloc;
void (*volatile g_release)(void*) = std::free;
}  // namespace

void* operator new(std::size_t size) {
  if (g_track_allocations.load(std::memory_order_relaxed)) {
    std::size_t seen = g_largest_allocation.load(std::memory_order_relaxed);
    while (size > seen && !g_largest_allocation.compare_exchange_weak(seen, size)) {
    }
  }
  if (void* memory = g_allocate(size == 0 ? 1 : size)) return memory;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return ::operator new(size);
}
void operator delete(void* memory) noexcept {
  g_release(memory);
}
void operator delete[](void* memory) noexcept {
  g_release(memory);
}
void operator delete(void* memory, std::size_t) noexcept {
  g_release(memory);
}
void operator delete[](void* memory, std::size_t) noexcept {
  g_release(memory);
}

namespace silnet {
namespace {

using silnet::testing::TempDir;
namespace fs = std::filesystem;

constexpr char kKind[] = "silhouettes/cam03";

// Independent bitwise CRC-32 (IEEE, reflected, as zlib) so the tests check the documented
// format rather than the implementation's own checksum call.
uint32_t ReferenceCrc32(const uint8_t* data, std::size_t size, uint32_t crc = 0) {
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int bit = 0; bit < 8; ++bit)
      crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void PutLe(std::vector<uint8_t>* out, uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i)
    out->push_back(static_cast<uint8_t>(value >> (8 * i)));
}

// A file header as documented in record_log.h.
std::vector<uint8_t> FileHeaderBytes(const std::string& kind, uint16_t version = 1,
                                     int64_t created_ns = 1'700'000'000'000'000'000) {
  std::vector<uint8_t> out = {'S', 'I', 'L', 'N', 'E', 'T', 'L', 'G'};
  PutLe(&out, version, 2);
  PutLe(&out, 64, 2);
  PutLe(&out, 0, 4);
  std::vector<uint8_t> padded(32, 0);
  std::copy(kind.begin(), kind.end(), padded.begin());
  out.insert(out.end(), padded.begin(), padded.end());
  PutLe(&out, static_cast<uint64_t>(created_ns), 8);
  PutLe(&out, 0, 4);
  PutLe(&out, ReferenceCrc32(out.data(), out.size()), 4);
  return out;
}

// A record as documented in record_log.h; `length` overrides the length field.
std::vector<uint8_t> RecordBytes(uint16_t type, uint16_t flags, const std::vector<uint8_t>& payload,
                                 int64_t length = -1) {
  std::vector<uint8_t> out = {0x53, 0x4C, 0x52, 0xEC};
  PutLe(&out, length >= 0 ? static_cast<uint64_t>(length) : payload.size(), 4);
  PutLe(&out, type, 2);
  PutLe(&out, flags, 2);
  uint32_t crc = ReferenceCrc32(out.data() + 4, 8);
  crc = ReferenceCrc32(payload.data(), payload.size(), crc);
  PutLe(&out, crc, 4);
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

// Deterministic payload bytes that never contain 0xEC, hence never a record magic, so
// resynchronisation finds exactly the records that were written.
std::vector<uint8_t> Payload(std::size_t size, uint32_t seed) {
  std::vector<uint8_t> out(size);
  uint32_t state = seed * 2654435761u + 12345u;
  for (uint8_t& byte : out) {
    state = state * 1664525u + 1013904223u;
    byte = static_cast<uint8_t>(state >> 24);
    if (byte == 0xEC) byte = 0xED;
  }
  return out;
}

struct Item {
  uint16_t type = 0;
  uint16_t flags = 0;
  std::vector<uint8_t> payload;
};

bool Same(const Record& record, const Item& item) {
  return record.type == item.type && record.flags == item.flags && record.payload == item.payload;
}

std::vector<Item> MakeItems(int count, std::size_t max_size, uint32_t seed) {
  std::vector<Item> items;
  for (int i = 0; i < count; ++i) {
    const std::size_t size = i % 5 == 0 ? 0 : (static_cast<std::size_t>(i) * 7919u) % max_size;
    items.push_back({static_cast<uint16_t>(i * 37 + 1), static_cast<uint16_t>(i % 3),
                     Payload(size, seed + static_cast<uint32_t>(i))});
  }
  return items;
}

std::vector<uint8_t> ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

void WriteBytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

void AppendBytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::app);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

// Writes `items` to a new log and returns each record's offset.
std::vector<uint64_t> WriteLog(const fs::path& path, const std::vector<Item>& items) {
  std::vector<uint64_t> offsets;
  RecordLogWriter writer;
  const RecordLogStatus opened = writer.Open(path, kKind);
  EXPECT_TRUE(opened.ok()) << opened.message();
  for (const Item& item : items) {
    offsets.push_back(writer.end_offset());
    const RecordLogStatus appended = writer.Append(item.type, item.payload, item.flags);
    EXPECT_TRUE(appended.ok()) << appended.message();
  }
  const RecordLogStatus closed = writer.Close();
  EXPECT_TRUE(closed.ok()) << closed.message();
  return offsets;
}

struct ReadResult {
  bool opened = false;
  std::string open_error;
  std::vector<Record> records;
  ReadStatus last = ReadStatus::kOk;
  uint64_t problem_offset = 0;
  std::string problem;
  RecordLogReaderStats stats;
};

ReadResult ReadAll(const fs::path& path, bool resync = false) {
  ReadResult result;
  RecordLogReader reader;
  RecordLogReaderOptions options;
  options.resync = resync;
  const RecordLogStatus status = reader.Open(path, options);
  result.opened = status.ok();
  result.open_error = status.message();
  if (!status.ok()) return result;
  for (int guard = 0; guard < 1'000'000; ++guard) {
    Record record;
    result.last = reader.Next(&record);
    if (result.last != ReadStatus::kOk) break;
    result.records.push_back(std::move(record));
  }
  result.problem_offset = reader.problem_offset();
  result.problem = reader.problem();
  result.stats = reader.stats();
  return result;
}

// Expects `records` to be exactly `items` (in order), optionally skipping index `skip`.
void ExpectRecords(const std::vector<Record>& records, const std::vector<Item>& items,
                   int skip = -1) {
  std::vector<const Item*> wanted;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (static_cast<int>(i) != skip) wanted.push_back(&items[i]);
  }
  ASSERT_EQ(records.size(), wanted.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    EXPECT_TRUE(Same(records[i], *wanted[i])) << "record " << i;
  }
}

uint64_t FileSize(const fs::path& path) {
  return fs::file_size(path);
}

// Raises the log level to error while alive: every torn tail a writer cuts logs a warning,
// which would flood the output of the loops below.
class QuietLogs {
 public:
  QuietLogs() : previous_(spdlog::get_level()) { spdlog::set_level(spdlog::level::err); }
  ~QuietLogs() { spdlog::set_level(previous_); }
  QuietLogs(const QuietLogs&) = delete;
  QuietLogs& operator=(const QuietLogs&) = delete;

 private:
  spdlog::level::level_enum previous_;
};

TEST(RecordLogTest, ReferenceCrcIsStandardCrc32) {
  const std::string check = "123456789";
  EXPECT_EQ(ReferenceCrc32(reinterpret_cast<const uint8_t*>(check.data()), check.size()),
            0xCBF43926u);
}

TEST(RecordLogTest, OnDiskBytesMatchTheDocumentedFormat) {
  TempDir dir;
  const fs::path path = dir / "log";
  const std::vector<uint8_t> payload = {1, 2, 3, 4, 5};
  RecordLogWriter writer;
  ASSERT_TRUE(writer.Open(path, kKind).ok());
  EXPECT_EQ(writer.end_offset(), kRecordLogFileHeaderBytes);
  ASSERT_TRUE(writer.Append(0x1234, payload, 0xBEEF).ok());
  ASSERT_TRUE(writer.Append(7, {}).ok());
  const auto created_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                              writer.header().created.time_since_epoch())
                              .count();
  ASSERT_TRUE(writer.Close().ok());

  std::vector<uint8_t> expected = FileHeaderBytes(kKind, 1, created_ns);
  const std::vector<uint8_t> first = RecordBytes(0x1234, 0xBEEF, payload);
  const std::vector<uint8_t> second = RecordBytes(7, 0, {});
  expected.insert(expected.end(), first.begin(), first.end());
  expected.insert(expected.end(), second.begin(), second.end());
  EXPECT_EQ(ReadBytes(path), expected);
}

TEST(RecordLogTest, RoundTripsManyRecordsOfVariedSizesAndTypes) {
  TempDir dir;
  const fs::path path = dir / "log";
  std::vector<Item> items = MakeItems(600, 3000, 1);
  items.push_back({0xFFFF, 0xFFFF, Payload(200'000, 99)});
  items.push_back({0, 0, {}});
  const auto before = std::chrono::system_clock::now();

  RecordLogWriter writer;
  const RecordLogStatus opened = writer.Open(path, kKind);
  ASSERT_TRUE(opened.ok()) << opened.message();
  EXPECT_TRUE(writer.recovery().initialised);
  EXPECT_EQ(writer.records(), 0u);
  std::vector<uint64_t> offsets;
  for (const Item& item : items) {
    offsets.push_back(writer.end_offset());
    ASSERT_TRUE(writer.Append(item.type, item.payload, item.flags).ok());
    EXPECT_EQ(writer.end_offset(), offsets.back() + kRecordHeaderBytes + item.payload.size());
  }
  EXPECT_EQ(writer.records(), items.size());
  ASSERT_TRUE(writer.Flush().ok());
  EXPECT_EQ(FileSize(path), writer.end_offset());
  ASSERT_TRUE(writer.Close().ok());
  EXPECT_FALSE(writer.is_open());
  EXPECT_TRUE(writer.Close().ok());

  RecordLogReader reader;
  RecordLogReaderOptions options;
  options.expected_stream_kind = kKind;
  const RecordLogStatus status = reader.Open(path, options);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.header().version, 1);
  EXPECT_EQ(reader.header().stream_kind, kKind);
  EXPECT_GE(reader.header().created, before - std::chrono::seconds(1));
  EXPECT_LE(reader.header().created, std::chrono::system_clock::now() + std::chrono::seconds(1));
  for (std::size_t i = 0; i < items.size(); ++i) {
    Record record;
    ASSERT_EQ(reader.Next(&record), ReadStatus::kOk) << i << ": " << reader.problem();
    EXPECT_EQ(record.offset, offsets[i]);
    EXPECT_TRUE(Same(record, items[i])) << i;
  }
  Record record;
  EXPECT_EQ(reader.Next(&record), ReadStatus::kEnd);
  EXPECT_EQ(reader.Next(&record), ReadStatus::kEnd);
  EXPECT_EQ(reader.stats().records, items.size());
  EXPECT_EQ(reader.stats().bytes_skipped, 0u);
}

TEST(RecordLogTest, LargestPayloadRoundTripsAndLongerIsAProgrammingError) {
  TempDir dir;
  const fs::path path = dir / "log";
  std::vector<uint8_t> payload(kMaxRecordPayloadBytes, 0x5A);
  payload.front() = 1;
  payload.back() = 2;
  RecordLogWriter writer;
  ASSERT_TRUE(writer.Open(path, kKind).ok());
  ASSERT_TRUE(writer.Append(3, payload).ok());
  payload.push_back(0);
  EXPECT_THROW((void)writer.Append(3, payload), CheckError);
  ASSERT_TRUE(writer.Close().ok());
  payload.pop_back();

  const ReadResult result = ReadAll(path);
  ASSERT_EQ(result.records.size(), 1u);
  EXPECT_EQ(result.records[0].payload, payload);
  EXPECT_EQ(result.last, ReadStatus::kEnd);
}

TEST(RecordLogTest, ReopeningAppendsAfterTheExistingRecords) {
  TempDir dir;
  const fs::path path = dir / "log";
  const std::vector<Item> items = MakeItems(10, 500, 2);
  WriteLog(path, std::vector<Item>(items.begin(), items.begin() + 5));
  const uint64_t size = FileSize(path);

  RecordLogWriter writer;
  const RecordLogStatus opened = writer.Open(path, kKind);
  ASSERT_TRUE(opened.ok()) << opened.message();
  EXPECT_FALSE(writer.recovery().initialised);
  EXPECT_FALSE(writer.recovery().tail_truncated);
  EXPECT_EQ(writer.recovery().records, 5u);
  EXPECT_EQ(writer.recovery().bytes_truncated, 0u);
  EXPECT_EQ(writer.records(), 5u);
  EXPECT_EQ(writer.end_offset(), size);
  for (std::size_t i = 5; i < items.size(); ++i) {
    ASSERT_TRUE(writer.Append(items[i].type, items[i].payload, items[i].flags).ok());
  }
  EXPECT_EQ(writer.records(), 10u);
  ASSERT_TRUE(writer.Close().ok());

  const ReadResult result = ReadAll(path);
  ExpectRecords(result.records, items);
  EXPECT_EQ(result.last, ReadStatus::kEnd);
}

TEST(RecordLogTest, OnlyOneWriterAtATime) {
  TempDir dir;
  const fs::path path = dir / "log";
  RecordLogWriter first;
  ASSERT_TRUE(first.Open(path, kKind).ok());
  RecordLogWriter second;
  const RecordLogStatus refused = second.Open(path, kKind);
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("another writer"), std::string::npos) << refused.message();
  EXPECT_FALSE(second.is_open());

  RecordLogWriter moved(std::move(first));
  EXPECT_FALSE(first.is_open());  // NOLINT(bugprone-use-after-move): moved-from state
  ASSERT_TRUE(moved.Append(1, Payload(10, 1)).ok());
  ASSERT_TRUE(moved.Close().ok());
  ASSERT_TRUE(second.Open(path, kKind).ok());
  EXPECT_EQ(second.records(), 1u);
}

TEST(RecordLogTest, ProgrammingErrorsThrowCheckError) {
  TempDir dir;
  RecordLogWriter writer;
  EXPECT_THROW((void)writer.Append(1, {}), CheckError);
  EXPECT_THROW((void)writer.Flush(), CheckError);
  EXPECT_THROW((void)writer.Open(dir / "a", ""), CheckError);
  EXPECT_THROW((void)writer.Open(dir / "a", std::string(33, 'k')), CheckError);
  EXPECT_THROW((void)writer.Open(dir / "a", std::string("a\0b", 3)), CheckError);
  EXPECT_FALSE(fs::exists(dir / "a"));
  ASSERT_TRUE(writer.Open(dir / "a", std::string(32, 'k')).ok());
  EXPECT_THROW((void)writer.Open(dir / "b", kKind), CheckError);
  RecordLogReader reader;
  Record record;
  EXPECT_THROW((void)reader.Next(&record), CheckError);
}

TEST(RecordLogTest, TruncationAtEveryByteOfTheLastRecordIsATornTail) {
  TempDir dir;
  QuietLogs quiet;
  const fs::path full = dir / "full";
  const std::vector<Item> items = {
      {1, 0, Payload(30, 1)}, {2, 0, {}}, {3, 1, Payload(100, 3)}, {4, 2, Payload(200, 4)}};
  const std::vector<uint64_t> offsets = WriteLog(full, items);
  const std::vector<uint8_t> bytes = ReadBytes(full);
  const uint64_t last = offsets.back();
  ASSERT_EQ(bytes.size(), last + kRecordHeaderBytes + 200);
  const std::vector<Item> kept(items.begin(), items.end() - 1);
  const Item fresh{9, 9, Payload(50, 9)};

  for (uint64_t cut = last; cut < bytes.size(); ++cut) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    const fs::path path = dir / "cut";
    WriteBytes(path, std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(cut)));

    const ReadResult read = ReadAll(path);
    ExpectRecords(read.records, kept);
    if (cut == last) {
      EXPECT_EQ(read.last, ReadStatus::kEnd);
    } else {
      EXPECT_EQ(read.last, ReadStatus::kTornTail) << read.problem;
      EXPECT_EQ(read.problem_offset, last);
    }

    RecordLogWriter writer;
    const RecordLogStatus opened = writer.Open(path, kKind);
    ASSERT_TRUE(opened.ok()) << opened.message();
    EXPECT_EQ(writer.recovery().records, kept.size());
    EXPECT_EQ(writer.recovery().tail_truncated, cut != last);
    EXPECT_EQ(writer.recovery().bytes_truncated, cut - last);
    EXPECT_EQ(FileSize(path), last);
    EXPECT_EQ(writer.end_offset(), last);
    ASSERT_TRUE(writer.Append(fresh.type, fresh.payload, fresh.flags).ok());
    ASSERT_TRUE(writer.Close().ok());

    std::vector<Item> now = kept;
    now.push_back(fresh);
    const ReadResult reread = ReadAll(path);
    ExpectRecords(reread.records, now);
    EXPECT_EQ(reread.last, ReadStatus::kEnd);
  }
}

TEST(RecordLogTest, TornFileHeaderIsRefusedByReadersAndReinitialisedByWriters) {
  TempDir dir;
  const std::vector<uint8_t> header = FileHeaderBytes(kKind);
  for (std::size_t cut = 0; cut < header.size(); ++cut) {
    SCOPED_TRACE("cut at " + std::to_string(cut));
    const fs::path path = dir / ("torn" + std::to_string(cut));
    WriteBytes(path, std::vector<uint8_t>(header.begin(), header.begin() + static_cast<long>(cut)));
    const ReadResult read = ReadAll(path);
    EXPECT_FALSE(read.opened);
    EXPECT_NE(read.open_error.find("incomplete"), std::string::npos) << read.open_error;

    RecordLogWriter writer;
    const RecordLogStatus opened = writer.Open(path, "other-kind");
    ASSERT_TRUE(opened.ok()) << opened.message();
    EXPECT_TRUE(writer.recovery().initialised);
    ASSERT_TRUE(writer.Append(5, Payload(5, 5)).ok());
    ASSERT_TRUE(writer.Close().ok());
    const ReadResult reread = ReadAll(path);
    ASSERT_EQ(reread.records.size(), 1u);
    EXPECT_EQ(reread.last, ReadStatus::kEnd);
  }
}

TEST(RecordLogTest, GarbageAfterTheLastRecordIsCorruptOnReadAndCutOnReopen) {
  TempDir dir;
  QuietLogs quiet;
  const fs::path path = dir / "log";
  const std::vector<Item> items = MakeItems(6, 300, 3);
  WriteLog(path, items);
  const uint64_t end = FileSize(path);
  // Zeros: what a crash can leave when the size was updated but the data never arrived.
  AppendBytes(path, std::vector<uint8_t>(4096, 0));

  const ReadResult read = ReadAll(path);
  ExpectRecords(read.records, items);
  EXPECT_EQ(read.last, ReadStatus::kCorrupt);
  EXPECT_EQ(read.problem_offset, end);

  RecordLogWriter writer;
  ASSERT_TRUE(writer.Open(path, kKind).ok());
  EXPECT_TRUE(writer.recovery().tail_truncated);
  EXPECT_EQ(writer.recovery().bytes_truncated, 4096u);
  EXPECT_FALSE(writer.recovery().tail_reason.empty());
  EXPECT_EQ(FileSize(path), end);
}

TEST(RecordLogTest, FlippedBitInAMiddleRecordIsCorruptAndResyncRecoversTheRest) {
  TempDir dir;
  const fs::path original = dir / "original";
  const std::vector<Item> items = {{1, 0, Payload(20, 1)},
                                   {2, 0, Payload(0, 2)},
                                   {3, 7, Payload(40, 3)},
                                   {4, 0, Payload(25, 4)},
                                   {5, 0, Payload(60, 5)}};
  const std::vector<uint64_t> offsets = WriteLog(original, items);
  const std::vector<uint8_t> bytes = ReadBytes(original);
  const int damaged = 2;
  const uint64_t begin = offsets[damaged];
  const uint64_t end = offsets[damaged + 1];

  for (uint64_t byte = begin; byte < end; ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      SCOPED_TRACE("byte " + std::to_string(byte) + " bit " + std::to_string(bit));
      std::vector<uint8_t> flipped = bytes;
      flipped[byte] ^= static_cast<uint8_t>(1u << bit);
      const fs::path path = dir / "flipped";
      WriteBytes(path, flipped);

      const ReadResult read = ReadAll(path);
      ExpectRecords(read.records, std::vector<Item>(items.begin(), items.begin() + damaged));
      EXPECT_EQ(read.last, ReadStatus::kCorrupt) << read.problem;
      EXPECT_EQ(read.problem_offset, begin);

      const ReadResult salvaged = ReadAll(path, /*resync=*/true);
      ExpectRecords(salvaged.records, items, damaged);
      EXPECT_EQ(salvaged.last, ReadStatus::kEnd);
      EXPECT_EQ(salvaged.stats.bytes_skipped, end - begin);
      EXPECT_EQ(salvaged.stats.corrupt_regions, 1u);

      RecordLogWriter writer;
      const RecordLogStatus refused = writer.Open(path, kKind);
      EXPECT_FALSE(refused.ok());
      EXPECT_NE(refused.message().find("salvage"), std::string::npos) << refused.message();
      EXPECT_EQ(ReadBytes(path), flipped);
    }
  }
}

TEST(RecordLogTest, FlippedBitInTheLastRecordIsNeverReadAndIsCutOnReopen) {
  TempDir dir;
  QuietLogs quiet;
  const fs::path original = dir / "original";
  const std::vector<Item> items = {{1, 0, Payload(20, 1)}, {2, 3, Payload(33, 2)}};
  const std::vector<uint64_t> offsets = WriteLog(original, items);
  const std::vector<uint8_t> bytes = ReadBytes(original);

  for (uint64_t byte = offsets[1]; byte < bytes.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      SCOPED_TRACE("byte " + std::to_string(byte) + " bit " + std::to_string(bit));
      std::vector<uint8_t> flipped = bytes;
      flipped[byte] ^= static_cast<uint8_t>(1u << bit);
      const fs::path path = dir / "flipped";
      WriteBytes(path, flipped);
      for (const bool resync : {false, true}) {
        const ReadResult read = ReadAll(path, resync);
        ExpectRecords(read.records, {items[0]});
        EXPECT_TRUE(read.last == ReadStatus::kCorrupt || read.last == ReadStatus::kTornTail)
            << ToString(read.last);
        EXPECT_EQ(read.problem_offset, offsets[1]);
      }
      RecordLogWriter writer;
      ASSERT_TRUE(writer.Open(path, kKind).ok());
      EXPECT_EQ(writer.records(), 1u);
      EXPECT_TRUE(writer.recovery().tail_truncated);
      EXPECT_EQ(FileSize(path), offsets[1]);
    }
  }
}

TEST(RecordLogTest, ResyncSkipsSeveralDamagedRegions) {
  TempDir dir;
  const fs::path path = dir / "log";
  const std::vector<Item> items = MakeItems(12, 400, 4);
  const std::vector<uint64_t> offsets = WriteLog(path, items);
  std::vector<uint8_t> bytes = ReadBytes(path);
  // Overwrite record 7's magic, then insert 100 bytes of junk before record 4.
  bytes[offsets[7]] = 'x';
  const std::vector<uint8_t> junk = Payload(100, 77);
  bytes.insert(bytes.begin() + static_cast<long>(offsets[4]), junk.begin(), junk.end());
  WriteBytes(path, bytes);

  const ReadResult plain = ReadAll(path);
  EXPECT_EQ(plain.records.size(), 4u);
  EXPECT_EQ(plain.last, ReadStatus::kCorrupt);
  EXPECT_EQ(plain.problem_offset, offsets[4]);

  const ReadResult salvaged = ReadAll(path, /*resync=*/true);
  ExpectRecords(salvaged.records, items, 7);
  EXPECT_EQ(salvaged.last, ReadStatus::kEnd);
  EXPECT_EQ(salvaged.stats.corrupt_regions, 2u);
  EXPECT_EQ(salvaged.stats.bytes_skipped, 100u + (offsets[8] - offsets[7]));
  EXPECT_EQ(salvaged.records[4].offset, offsets[4] + 100);
}

TEST(RecordLogTest, FlippedBitInTheFileHeaderIsRefused) {
  TempDir dir;
  const fs::path original = dir / "original";
  WriteLog(original, MakeItems(3, 50, 5));
  const std::vector<uint8_t> bytes = ReadBytes(original);
  for (std::size_t byte = 0; byte < kRecordLogFileHeaderBytes; ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      SCOPED_TRACE("byte " + std::to_string(byte) + " bit " + std::to_string(bit));
      std::vector<uint8_t> flipped = bytes;
      flipped[byte] ^= static_cast<uint8_t>(1u << bit);
      const fs::path path = dir / "flipped";
      WriteBytes(path, flipped);
      EXPECT_FALSE(ReadAll(path).opened);
      RecordLogWriter writer;
      EXPECT_FALSE(writer.Open(path, kKind).ok());
      EXPECT_EQ(ReadBytes(path), flipped);
    }
  }
}

TEST(RecordLogTest, ForeignFilesAndOtherStreamKindsAreRefusedUntouched) {
  TempDir dir;
  const fs::path png = dir / "image.png";
  std::vector<uint8_t> png_bytes(300, 0x42);
  const uint8_t png_signature[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::copy(std::begin(png_signature), std::end(png_signature), png_bytes.begin());
  WriteBytes(png, png_bytes);
  const fs::path short_text = dir / "notes.txt";
  WriteBytes(short_text, {'h', 'e', 'l', 'l', 'o'});

  for (const fs::path& path : {png, short_text}) {
    SCOPED_TRACE(path.string());
    const std::vector<uint8_t> before = ReadBytes(path);
    RecordLogWriter writer;
    const RecordLogStatus refused = writer.Open(path, kKind);
    EXPECT_FALSE(refused.ok());
    EXPECT_NE(refused.message().find("not a silnet record log"), std::string::npos)
        << refused.message();
    EXPECT_NE(refused.message().find(path.string()), std::string::npos) << refused.message();
    const ReadResult read = ReadAll(path);
    EXPECT_FALSE(read.opened);
    EXPECT_NE(read.open_error.find("not a silnet record log"), std::string::npos)
        << read.open_error;
    EXPECT_EQ(ReadBytes(path), before);
  }

  const fs::path log = dir / "log";
  WriteLog(log, MakeItems(3, 50, 6));
  const std::vector<uint8_t> before = ReadBytes(log);
  RecordLogWriter writer;
  const RecordLogStatus other_kind = writer.Open(log, "depth/cam03");
  EXPECT_FALSE(other_kind.ok());
  EXPECT_NE(other_kind.message().find(kKind), std::string::npos) << other_kind.message();
  EXPECT_NE(other_kind.message().find("depth/cam03"), std::string::npos) << other_kind.message();
  EXPECT_EQ(ReadBytes(log), before);

  RecordLogReader reader;
  RecordLogReaderOptions options;
  options.expected_stream_kind = "depth/cam03";
  const RecordLogStatus read_other = reader.Open(log, options);
  EXPECT_FALSE(read_other.ok());
  EXPECT_NE(read_other.message().find("depth/cam03"), std::string::npos) << read_other.message();

  const fs::path newer = dir / "newer";
  WriteBytes(newer, FileHeaderBytes(kKind, 2));
  const RecordLogStatus version = writer.Open(newer, kKind);
  EXPECT_FALSE(version.ok());
  EXPECT_NE(version.message().find("version 2"), std::string::npos) << version.message();
  EXPECT_EQ(FileSize(newer), kRecordLogFileHeaderBytes);

  const RecordLogStatus folder = writer.Open(dir.path(), kKind);
  EXPECT_FALSE(folder.ok());
  EXPECT_FALSE(writer.is_open());
  const RecordLogStatus missing = reader.Open(dir / "missing");
  EXPECT_FALSE(missing.ok());
  EXPECT_EQ(missing.error_number(), ENOENT);
}

TEST(RecordLogTest, HostileLengthFieldsAreNeverAllocated) {
  TempDir dir;
  QuietLogs quiet;
  const std::vector<uint8_t> header = FileHeaderBytes(kKind);
  const std::vector<uint8_t> good = RecordBytes(1, 0, Payload(10, 1));
  struct Case {
    std::string name;
    int64_t length;
    ReadStatus expected;
  };
  const std::vector<Case> cases = {
      {"gigabytes", 0xFFFFFFF0, ReadStatus::kCorrupt},
      {"just over the limit", kMaxRecordPayloadBytes + 1, ReadStatus::kCorrupt},
      {"within the limit but past the end", kMaxRecordPayloadBytes, ReadStatus::kTornTail}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path path = dir / "hostile";
    std::vector<uint8_t> bytes = header;
    bytes.insert(bytes.end(), good.begin(), good.end());
    const std::vector<uint8_t> hostile = RecordBytes(2, 0, Payload(32, 2), c.length);
    bytes.insert(bytes.end(), hostile.begin(), hostile.end());
    WriteBytes(path, bytes);

    for (const bool resync : {false, true}) {
      g_largest_allocation = 0;
      g_track_allocations = true;
      const ReadResult read = ReadAll(path, resync);
      g_track_allocations = false;
      EXPECT_EQ(read.records.size(), 1u);
      EXPECT_EQ(read.last, c.expected) << read.problem;
      EXPECT_LT(g_largest_allocation.load(), std::size_t{1} << 20);
    }
    g_largest_allocation = 0;
    g_track_allocations = true;
    RecordLogWriter writer;
    const RecordLogStatus opened = writer.Open(path, kKind);
    g_track_allocations = false;
    ASSERT_TRUE(opened.ok()) << opened.message();
    EXPECT_TRUE(writer.recovery().tail_truncated);
    EXPECT_EQ(writer.records(), 1u);
    EXPECT_LT(g_largest_allocation.load(), std::size_t{1} << 20);
  }
}

TEST(RecordLogTest, RandomDamageNeverYieldsBadRecordsOrCrashes) {
  TempDir dir;
  QuietLogs quiet;
  const fs::path original = dir / "original";
  const std::vector<Item> items = MakeItems(40, 200, 8);
  WriteLog(original, items);
  const std::vector<uint8_t> bytes = ReadBytes(original);
  std::mt19937 random(42);
  auto is_original = [&](const Record& record) {
    return std::any_of(items.begin(), items.end(),
                       [&](const Item& item) { return Same(record, item); });
  };
  for (int round = 0; round < 400; ++round) {
    std::vector<uint8_t> damaged = bytes;
    const int kind = round % 4;
    std::uniform_int_distribution<std::size_t> position(kRecordLogFileHeaderBytes,
                                                        damaged.size() - 1);
    if (kind == 0) {
      for (int i = 0; i < 5; ++i)
        damaged[position(random)] = static_cast<uint8_t>(random());
    } else if (kind == 1) {
      damaged.resize(position(random));
    } else if (kind == 2) {
      std::vector<uint8_t> junk(random() % 300);
      for (uint8_t& byte : junk)
        byte = static_cast<uint8_t>(random());
      damaged.insert(damaged.begin() + static_cast<long>(position(random)), junk.begin(),
                     junk.end());
    } else {
      damaged.resize(kRecordLogFileHeaderBytes + random() % 2000);
      for (std::size_t i = kRecordLogFileHeaderBytes; i < damaged.size(); ++i) {
        damaged[i] = static_cast<uint8_t>(random() % 4 == 0 ? 0x53 : random());
      }
    }
    const fs::path path = dir / "damaged";
    WriteBytes(path, damaged);
    for (const bool resync : {false, true}) {
      const ReadResult read = ReadAll(path, resync);
      ASSERT_TRUE(read.opened);
      EXPECT_NE(read.last, ReadStatus::kOk);
      EXPECT_NE(read.last, ReadStatus::kIoError);
      for (const Record& record : read.records)
        EXPECT_TRUE(is_original(record)) << round;
    }
    RecordLogWriter writer;
    if (writer.Open(path, kKind).ok()) {
      ASSERT_TRUE(writer.Append(1, Payload(3, 3)).ok());
      ASSERT_TRUE(writer.Close().ok());
      const ReadResult reread = ReadAll(path);
      EXPECT_EQ(reread.last, ReadStatus::kEnd) << round << ": " << reread.problem;
    }
  }
}

// Lowers the soft file-size limit (writes past it fail with EFBIG instead of raising
// SIGXFSZ) and restores both on destruction.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(uint64_t bytes) {
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    ::getrlimit(RLIMIT_FSIZE, &previous_);
    rlimit limit = previous_;
    limit.rlim_cur = static_cast<rlim_t>(bytes);
    ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &previous_);
    std::signal(SIGXFSZ, previous_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  bool ok() const { return ok_; }

 private:
  rlimit previous_{};
  void (*previous_handler_)(int) = SIG_DFL;
  bool ok_ = false;
};

TEST(RecordLogTest, FailedWritesLeaveARecordBoundaryAndAppendsResume) {
  TempDir dir;
  const fs::path path = dir / "log";
  RecordLogWriter writer;
  ASSERT_TRUE(writer.Open(path, kKind).ok());
  std::vector<Item> written;
  for (int i = 0; i < 10; ++i) {
    written.push_back({static_cast<uint16_t>(i), 0, Payload(100, static_cast<uint32_t>(i))});
    ASSERT_TRUE(writer.Append(written.back().type, written.back().payload).ok());
  }
  ASSERT_TRUE(writer.Flush().ok());
  const uint64_t boundary = writer.end_offset();
  const Item big{50, 1, Payload(1000, 50)};
  const Item small{51, 2, Payload(100, 51)};

  RecordLogStatus too_big = RecordLogStatus::Ok();
  RecordLogStatus fits = RecordLogStatus::Ok();
  RecordLogStatus too_big_again = RecordLogStatus::Ok();
  uint64_t size_after_failure = 0;
  uint64_t size_after_small = 0;
  uint64_t size_after_second_failure = 0;
  {
    FileSizeLimit limit(boundary + 300);  // a partial record fits, a whole big one does not
    ASSERT_TRUE(limit.ok());
    too_big = writer.Append(big.type, big.payload, big.flags);
    size_after_failure = FileSize(path);
    fits = writer.Append(small.type, small.payload, small.flags);
    size_after_small = FileSize(path);
    too_big_again = writer.Append(big.type, big.payload, big.flags);
    size_after_second_failure = FileSize(path);
  }
  EXPECT_FALSE(too_big.ok());
  EXPECT_EQ(too_big.error_number(), EFBIG);
  EXPECT_NE(too_big.message().find(path.string()), std::string::npos) << too_big.message();
  EXPECT_EQ(size_after_failure, boundary);
  EXPECT_TRUE(fits.ok()) << fits.message();
  written.push_back(small);
  EXPECT_EQ(size_after_small, boundary + kRecordHeaderBytes + small.payload.size());
  EXPECT_FALSE(too_big_again.ok());
  EXPECT_EQ(size_after_second_failure, size_after_small);
  EXPECT_EQ(writer.records(), written.size());

  // Space is back: the caller's retry succeeds.
  ASSERT_TRUE(writer.Append(big.type, big.payload, big.flags).ok());
  written.push_back(big);
  ASSERT_TRUE(writer.Flush().ok());
  ASSERT_TRUE(writer.Close().ok());
  const ReadResult read = ReadAll(path);
  ExpectRecords(read.records, written);
  EXPECT_EQ(read.last, ReadStatus::kEnd);
}

TEST(RecordLogTest, ReaderWaitsAtATornRecordAndContinuesWhenItCompletes) {
  TempDir dir;
  const fs::path path = dir / "log";
  const std::vector<Item> items = MakeItems(3, 100, 9);
  WriteLog(path, std::vector<Item>(items.begin(), items.begin() + 2));
  const std::vector<uint8_t> third = RecordBytes(items[2].type, items[2].flags, items[2].payload);
  const uint64_t third_at = FileSize(path);

  RecordLogReader reader;
  ASSERT_TRUE(reader.Open(path).ok());
  Record record;
  ASSERT_EQ(reader.Next(&record), ReadStatus::kOk);
  ASSERT_EQ(reader.Next(&record), ReadStatus::kOk);
  EXPECT_EQ(reader.Next(&record), ReadStatus::kEnd);
  // Another process writes the third record a few bytes at a time.
  std::size_t written = 0;
  for (const std::size_t step : {std::size_t{3}, std::size_t{9}, std::size_t{20}}) {
    AppendBytes(path, std::vector<uint8_t>(third.begin() + static_cast<long>(written),
                                           third.begin() + static_cast<long>(written + step)));
    written += step;
    EXPECT_EQ(reader.Next(&record), ReadStatus::kTornTail) << written;
    EXPECT_EQ(reader.problem_offset(), third_at);
    EXPECT_EQ(reader.offset(), third_at);
    EXPECT_TRUE(record.payload.empty());
  }
  AppendBytes(path, std::vector<uint8_t>(third.begin() + static_cast<long>(written), third.end()));
  ASSERT_EQ(reader.Next(&record), ReadStatus::kOk);
  EXPECT_TRUE(Same(record, items[2]));
  EXPECT_EQ(record.offset, third_at);
  EXPECT_EQ(reader.Next(&record), ReadStatus::kEnd);
  EXPECT_TRUE(reader.problem().empty());
}

TEST(RecordLogTest, ReaderFollowsAWriterInAnotherProcess) {
  TempDir dir;
  const fs::path path = dir / "log";
  const std::vector<Item> items = MakeItems(300, 5000, 10);
  {
    RecordLogWriter writer;
    ASSERT_TRUE(writer.Open(path, kKind).ok());
  }
  RecordLogReader reader;
  ASSERT_TRUE(reader.Open(path).ok());

  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    RecordLogWriter writer;
    if (!writer.Open(path, kKind).ok()) ::_exit(2);
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (!writer.Append(items[i].type, items[i].payload, items[i].flags).ok()) ::_exit(3);
      if (i % 10 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ::_exit(writer.Close().ok() ? 0 : 4);
  }

  std::vector<Record> records;
  int waits = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (records.size() < items.size() && std::chrono::steady_clock::now() < deadline) {
    Record record;
    const ReadStatus status = reader.Next(&record);
    if (status == ReadStatus::kOk) {
      records.push_back(std::move(record));
      continue;
    }
    ASSERT_TRUE(status == ReadStatus::kEnd || status == ReadStatus::kTornTail)
        << ToString(status) << ": " << reader.problem();
    ++waits;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  int wait_status = 0;
  ASSERT_EQ(::waitpid(child, &wait_status, 0), child);
  ASSERT_TRUE(WIFEXITED(wait_status));
  EXPECT_EQ(WEXITSTATUS(wait_status), 0);
  ExpectRecords(records, items);
  EXPECT_GT(waits, 0);
  Record record;
  EXPECT_EQ(reader.Next(&record), ReadStatus::kEnd);
}

}  // namespace
}  // namespace silnet

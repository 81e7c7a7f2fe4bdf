#include "node/publish/frame_recorder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include "node/publish/frame_history.h"
#include "shared/io/session_log_reader.h"
#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet::node {
namespace {

FrameRecord Frame(uint64_t index, size_t payload_bytes) {
  FrameRecord r;
  r.camera_id = "cam03";
  r.session = 7;
  r.frame_index = index;
  r.width = 640;
  r.height = 480;
  r.payload.assign(payload_bytes, static_cast<uint8_t>(index));
  return r;
}

TEST(FrameRecorder, AFullDiskPausesRecordingAndNothingIsLostWhenSpaceReturns) {
  testing::TempDir dir;
  FrameRecorder recorder(dir.path(), "cam03");
  recorder.Open();
  for (uint64_t i = 0; i < 10; ++i) {
    recorder.Add(SessionRecordType::kHullFrame, SerializeFrameRecord(Frame(i, 200)));
  }
  // Limit the file size just above what is written: the next records do not fit.
  signal(SIGXFSZ, SIG_IGN);
  rlimit saved{};
  getrlimit(RLIMIT_FSIZE, &saved);
  const auto size = std::filesystem::file_size(recorder.path());
  rlimit limit = saved;
  limit.rlim_cur = size + 100;
  setrlimit(RLIMIT_FSIZE, &limit);
  for (uint64_t i = 10; i < 20; ++i) {
    recorder.Add(SessionRecordType::kHullFrame, SerializeFrameRecord(Frame(i, 200)));
  }
  const RecorderCounters paused = recorder.counters();
  EXPECT_FALSE(paused.last_error.empty());
  EXPECT_EQ(paused.pending, 10u);
  EXPECT_GT(paused.failures, 0u);
  setrlimit(RLIMIT_FSIZE, &saved);
  recorder.Add(SessionRecordType::kHullFrame, SerializeFrameRecord(Frame(20, 200)));
  recorder.Flush();
  const RecorderCounters resumed = recorder.counters();
  EXPECT_TRUE(resumed.last_error.empty());
  EXPECT_EQ(resumed.pending, 0u);
  EXPECT_EQ(resumed.written, 21u);
  EXPECT_EQ(resumed.lost, 0u);
  const auto sessions = ReadSessionLog(recorder.path());
  ASSERT_EQ(sessions.size(), 1u);
  ASSERT_EQ(sessions[0].hulls.size(), 21u);
  for (uint64_t i = 0; i < 21; ++i)
    EXPECT_EQ(sessions[0].hulls[i], Frame(i, 200));
}

TEST(FrameRecorder, AnUnwritableFolderIsAClearError) {
  FrameRecorder recorder("/proc/silnet-cannot-create", "cam00");
  EXPECT_THAT([&] { recorder.Open(); }, ::testing::ThrowsMessage<InputError>(
                                            ::testing::HasSubstr("/proc/silnet-cannot-create")));
}

TEST(FrameHistory, KeepsTheNewestFramesInOrder) {
  FrameHistory history(5);
  for (uint64_t i = 0; i < 12; ++i)
    history.Add(HistoryEntry{Frame(i, 4), std::nullopt});
  EXPECT_EQ(history.size(), 5u);
  EXPECT_EQ(history.Span(), std::make_optional(std::make_pair<uint64_t, uint64_t>(7, 11)));
  const auto range = history.Range(5, 9);
  ASSERT_EQ(range.size(), 3u);
  EXPECT_EQ(range[0].hull.frame_index, 7u);
  EXPECT_EQ(range[2].hull.frame_index, 9u);
  EXPECT_TRUE(history.Range(20, 30).empty());
}

}  // namespace
}  // namespace silnet::node

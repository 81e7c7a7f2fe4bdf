#include "aggregator/ingest/session_store.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "shared/util/check.h"
#include "shared/util/frame_index_set.h"
#include "tests/support/temp_dir.h"

namespace silnet::aggregator {
namespace {

FrameRecord Frame(const std::string& camera, uint32_t session, uint64_t index) {
  FrameRecord r;
  r.camera_id = camera;
  r.session = session;
  r.frame_index = index;
  r.width = 320;
  r.height = 240;
  r.payload = {1, 2, 3, static_cast<uint8_t>(index)};
  return r;
}

TEST(FrameIndexSet, InsertsMergesAndReportsGaps) {
  FrameIndexSet set;
  std::mt19937_64 rng(4);
  std::vector<uint64_t> order(200);
  for (uint64_t i = 0; i < 200; ++i)
    order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  for (uint64_t i : order) {
    if (i % 17 != 3) {
      EXPECT_TRUE(set.Insert(i));
    }
  }
  EXPECT_FALSE(set.Insert(order[0] % 17 == 3 ? order[1] : order[0]));
  EXPECT_EQ(set.size(), 200u - 12u);
  const auto gaps = set.Missing(0);
  ASSERT_EQ(gaps.size(), 12u);
  EXPECT_EQ(gaps[0], (FrameRange{3, 3}));
  EXPECT_FALSE(set.Contains(20));
  EXPECT_TRUE(set.Contains(21));
  EXPECT_EQ(set.min(), 0u);
  EXPECT_EQ(set.max(), 199u);
}

TEST(SessionStore, StoresOnceSurvivesReopenAndReadsBackSorted) {
  testing::TempDir dir;
  {
    SessionStore store(dir.path());
    store.Open();
    for (uint64_t i : {0u, 2u, 1u, 3u})
      EXPECT_EQ(store.Add(SessionRecordType::kHullFrame, Frame("c1", 5, i)), StoreResult::kStored);
    EXPECT_EQ(store.Add(SessionRecordType::kHullFrame, Frame("c1", 5, 2)), StoreResult::kDuplicate);
    EXPECT_EQ(store.Add(SessionRecordType::kContour, Frame("c1", 5, 2)), StoreResult::kStored);
    EXPECT_EQ(store.Add(SessionRecordType::kHullFrame, Frame("c1", 6, 0)), StoreResult::kStored);
    CameraInfoRecord info;
    info.camera_id = "c1";
    info.width = 320;
    info.parameters["k"] = "v=1\nline";
    store.AddCameraInfo(info);
  }
  // Append a torn record by hand, as a crash would leave it.
  std::ofstream(SessionLogPath(dir.path(), "c1"), std::ios::app | std::ios::binary) << "SLR";
  SessionStore reopened(dir.path());
  reopened.Open();
  EXPECT_EQ(reopened.Add(SessionRecordType::kHullFrame, Frame("c1", 5, 3)),
            StoreResult::kDuplicate);
  EXPECT_EQ(reopened.Add(SessionRecordType::kHullFrame, Frame("c1", 5, 4)), StoreResult::kStored);
  EXPECT_EQ(reopened.HullFrames("c1", 5).size(), 5u);
  EXPECT_EQ(reopened.Sessions("c1"), (std::vector<uint32_t>{5, 6}));
  reopened.Flush();
  SessionReadReport report;
  const auto sessions = ReadSessionLog(SessionLogPath(dir.path(), "c1"), &report);
  ASSERT_EQ(sessions.size(), 2u);
  ASSERT_EQ(sessions[0].hulls.size(), 5u);
  for (uint64_t i = 0; i < 5; ++i)
    EXPECT_EQ(sessions[0].hulls[i], Frame("c1", 5, i));
  EXPECT_EQ(sessions[0].contours.size(), 1u);
  EXPECT_EQ(sessions[0].info.parameters.at("k"), "v=1\nline");
  EXPECT_EQ(report.duplicates, 0u);
  EXPECT_EQ(report.malformed, 0u);
}

TEST(SessionStore, RefusesAForeignFile) {
  testing::TempDir dir;
  std::ofstream(dir / "x.silnetlog")
      << "definitely not a session log, but long enough to have a header....";
  SessionStore store(dir.path());
  EXPECT_THROW(store.Open(), InputError);
}

}  // namespace
}  // namespace silnet::aggregator

// The live job's in-memory window of the newest hull frames (aggregator/live).

#include "aggregator/live/recent_silhouettes.h"

#include <gtest/gtest.h>

namespace silnet::aggregator {
namespace {

FrameRecord Record(const std::string& camera, uint32_t session, uint64_t index) {
  FrameRecord r;
  r.camera_id = camera;
  r.session = session;
  r.frame_index = index;
  r.width = 640;
  r.height = 480;
  return r;  // an empty payload decodes as a frame flagged unusable; enough here
}

TEST(RecentSilhouettes, WindowsDropsAndSessions) {
  RecentSilhouettes recent;
  EXPECT_FALSE(recent.Holds(0));
  for (uint64_t k = 0; k < 100; ++k) {
    recent.Add(Record("cam01", 3, k));
    if (k >= 10) recent.Add(Record("cam00", 3, k));  // joined late
  }
  EXPECT_FALSE(recent.Holds(5));
  EXPECT_TRUE(recent.Holds(10));
  const auto window = recent.Window(40, 20);
  ASSERT_EQ(window.size(), 2u);
  EXPECT_EQ(window[0].camera_id, "cam00");
  ASSERT_EQ(window[0].frames.size(), 20u);
  EXPECT_EQ(window[0].frames.front().index, 40u);
  EXPECT_EQ(window[1].frames.back().index, 59u);
  EXPECT_EQ(window[1].width, 640);

  recent.DropBefore(60);
  EXPECT_EQ(recent.size(), 80u);
  EXPECT_FALSE(recent.Holds(59));
  EXPECT_EQ(recent.Window(40, 30)[0].frames.front().index, 60u);
  recent.Add(Record("cam00", 3, 50));  // below the floor: not kept
  EXPECT_EQ(recent.size(), 80u);

  recent.Add(Record("cam00", 2, 99));  // an older session: ignored
  recent.Add(Record("cam01", 4, 70));  // a restarted node: its old session goes
  EXPECT_EQ(recent.size(), 41u);
  const auto after = recent.Window(60, 40);
  ASSERT_EQ(after.size(), 2u);
  ASSERT_EQ(after[1].frames.size(), 1u);
  EXPECT_EQ(after[1].frames[0].index, 70u);
}

}  // namespace
}  // namespace silnet::aggregator

#include "shared/io/dataset_layout.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

TEST(DatasetLayout, FindsCamerasAndCountsConsecutiveImages) {
  testing::TempDir dir;
  const DatasetLayout layout(dir.path());
  std::filesystem::create_directories(layout.MasksDir("camB"));
  std::filesystem::create_directories(layout.FramesDir("camA"));
  std::filesystem::create_directories(dir / "not-a-camera");
  for (int i : {0, 1, 2, 4})
    std::ofstream(layout.MaskPath("camB", i)) << "x";
  EXPECT_EQ(layout.CameraIds(), (std::vector<std::string>{"camA", "camB"}));
  EXPECT_EQ(layout.CountImages("camB", "masks"), 3);
  EXPECT_EQ(layout.CountImages("camA", "frames"), 0);
  EXPECT_EQ(layout.MaskPath("camB", 42).filename().string(), "000042.png");
}

}  // namespace
}  // namespace silnet

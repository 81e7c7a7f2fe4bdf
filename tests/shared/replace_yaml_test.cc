#include "shared/io/replace_yaml.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "shared/util/check.h"
#include "tests/support/temp_dir.h"

namespace silnet {
namespace {

TEST(ReplaceYaml, ReplacesTheWholeFileAndLeavesNothingBeside) {
  testing::TempDir dir;
  const std::filesystem::path path = dir / "state.yaml";
  ReplaceYaml(path, [](cv::FileStorage& fs) {
    fs << "value" << 1 << "name"
       << "first";
  });
  ReplaceYaml(path, [](cv::FileStorage& fs) { fs << "value" << 2; });
  cv::FileStorage read(path.string(), cv::FileStorage::READ);
  ASSERT_TRUE(read.isOpened());
  EXPECT_EQ(static_cast<int>(read["value"]), 2);
  EXPECT_TRUE(read["name"].empty()) << "the old file's keys are gone";
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
    ++files;
  EXPECT_EQ(files, 1) << "no partial file is left";
}

TEST(ReplaceYaml, UnwritableFolderIsAnInputErrorAndKeepsTheOldFile) {
  testing::TempDir dir;
  EXPECT_THROW(ReplaceYaml(dir / "missing" / "state.yaml", [](cv::FileStorage&) {}), InputError);
  const std::filesystem::path path = dir / "state.yaml";
  ReplaceYaml(path, [](cv::FileStorage& fs) { fs << "value" << 1; });
  // A writer that fails midway leaves the previous file as it was.
  EXPECT_THROW(ReplaceYaml(path,
                           [](cv::FileStorage& fs) {
                             fs << "value" << 2;
                             throw InputError("the writer gave up");
                           }),
               InputError);
  cv::FileStorage read(path.string(), cv::FileStorage::READ);
  EXPECT_EQ(static_cast<int>(read["value"]), 1);
}

}  // namespace
}  // namespace silnet

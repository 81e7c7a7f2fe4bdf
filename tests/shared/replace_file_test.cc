#include "shared/io/replace_file.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "shared/io/replace_yaml.h"
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

std::string ReadWhole(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ReplaceFile, ReaderSeesOnlyWholeVersionsWhileTheFileIsRewritten) {
  testing::TempDir dir;
  const std::filesystem::path path = dir / "report.html";
  // Two versions of different lengths: a file truncated and rewritten in place would show a
  // reader an empty, shortened or mixed file.
  const std::string small(1000, 'a'), large(200000, 'b');
  ReplaceFile(path, small);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int i = 0; i < 300; ++i)
      ReplaceFile(path, i % 2 == 0 ? large : small);
    done = true;
  });
  int reads = 0, torn = 0;
  while (!done || reads == 0) {
    const std::string seen = ReadWhole(path);
    ++reads;
    if (seen != small && seen != large) ++torn;
  }
  writer.join();
  EXPECT_EQ(torn, 0) << "of " << reads << " reads";
  EXPECT_EQ(ReadWhole(path), small);
}

TEST(ReplaceFile, UnwritableFolderIsAnInputErrorAndLeavesNothing) {
  testing::TempDir dir;
  EXPECT_THROW(ReplaceFile(dir / "missing" / "page.html", "text"), InputError);
  const std::filesystem::path path = dir / "page.html";
  ReplaceFile(path, "first");
  // A writer that gives up midway leaves the previous file and no partial one.
  EXPECT_THROW(ReplaceFileThrough(path,
                                  [](const std::filesystem::path& partial) {
                                    std::ofstream(partial) << "half";
                                    throw InputError("the writer gave up");
                                  }),
               InputError);
  EXPECT_EQ(ReadWhole(path), "first");
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
    ++files;
  EXPECT_EQ(files, 1);
}

}  // namespace
}  // namespace silnet

// The fuzz targets in the ordinary suite: every seed, deterministic mutations of the seeds
// (byte flips, truncations, insertions), and every input kept in tests/fuzz/regressions/
// (inputs that once crashed a target) run through the same code as under libFuzzer. A
// broken invariant aborts, so passing means no crash and no invariant broken.

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "tests/fuzz/fuzz_inputs.h"
#include "tests/support/byte_mutation.h"

namespace silnet::fuzz {
namespace {

using Target = int (*)(std::span<const uint8_t>);

const std::filesystem::path kRegressions =
    std::filesystem::path(SILNET_SOURCE_DIR) / "tests/fuzz/regressions";

// Runs `target` on each seed and on `mutations` mutations of each.
void RunSeedsAndMutations(Target target, const std::vector<std::vector<uint8_t>>& seeds,
                          int mutations) {
  std::mt19937 random(20261121);
  for (const auto& seed : seeds) {
    target(seed);
    for (int m = 0; m < mutations; ++m)
      target(testing::MutateBytes(seed, random));
  }
}

// Runs `target` on every file in tests/fuzz/regressions/<name>/; returns how many.
int RunRegressions(Target target, const std::string& name) {
  int count = 0;
  const std::filesystem::path dir = kRegressions / name;
  if (!std::filesystem::is_directory(dir)) return 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::ifstream in(entry.path(), std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                     std::istreambuf_iterator<char>());
    target(bytes);
    ++count;
  }
  return count;
}

TEST(FuzzRegression, FrameSamples) {
  const auto seeds = FrameSampleSeeds();
  ASSERT_EQ(seeds.size(), 6u);
  // Every seed is a valid sample: a hull (accepted as hull; as contours only by chance) or
  // a contour payload.
  for (const auto& seed : seeds)
    EXPECT_GE(FuzzFrameSample(seed), 1);
  RunSeedsAndMutations(&FuzzFrameSample, seeds, 2000);
  std::printf("frame_sample regressions: %d\n", RunRegressions(&FuzzFrameSample, "frame_sample"));
}

TEST(FuzzRegression, SessionLogs) {
  const auto seeds = SessionLogSeeds();
  ASSERT_EQ(seeds.size(), 2u);
  EXPECT_EQ(FuzzSessionLog(seeds[0]), 6);  // two sessions of three frames, one duplicate
  EXPECT_EQ(FuzzSessionLog(seeds[1]), 6);  // the torn tail was the duplicate
  RunSeedsAndMutations(&FuzzSessionLog, seeds, 2000);
  std::printf("session_log regressions: %d\n", RunRegressions(&FuzzSessionLog, "session_log"));
}

TEST(FuzzRegression, InputFiles) {
  const auto seeds = InputFileSeeds();
  ASSERT_EQ(seeds.size(), 2u);
  for (const auto& seed : seeds)
    EXPECT_EQ(FuzzInputFile(seed), 1);
  // Fewer mutations: each YAML file is parsed in a child process first (yaml_guard.h).
  RunSeedsAndMutations(&FuzzInputFile, seeds, 500);
  std::printf("input_file regressions: %d\n", RunRegressions(&FuzzInputFile, "input_file"));
}

}  // namespace
}  // namespace silnet::fuzz

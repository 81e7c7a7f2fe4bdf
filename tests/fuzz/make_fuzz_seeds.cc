// silnet-make-fuzz-seeds OUT: writes the fuzz targets' seed corpora, OUT/frame_sample/,
// OUT/session_log/ and OUT/input_file/, from the real encoders and writers.
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tests/fuzz/fuzz_inputs.h"

namespace {

void WriteCorpus(const std::filesystem::path& dir, const std::vector<std::vector<uint8_t>>& seeds) {
  std::filesystem::create_directories(dir);
  for (size_t i = 0; i < seeds.size(); ++i) {
    std::ofstream out(dir / ("seed-" + std::to_string(i)), std::ios::binary);
    out.write(reinterpret_cast<const char*>(seeds[i].data()),
              static_cast<std::streamsize>(seeds[i].size()));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: silnet-make-fuzz-seeds OUT\n");
    return 2;
  }
  const std::filesystem::path out = argv[1];
  WriteCorpus(out / "frame_sample", silnet::fuzz::FrameSampleSeeds());
  WriteCorpus(out / "session_log", silnet::fuzz::SessionLogSeeds());
  WriteCorpus(out / "input_file", silnet::fuzz::InputFileSeeds());
  return 0;
}

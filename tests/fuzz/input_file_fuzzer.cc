// libFuzzer target: calibration YAML and point-cloud PLY files as users hand them to the jobs.
#include "tests/fuzz/fuzz_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)silnet::fuzz::FuzzInputFile({data, size});
  return 0;
}

// libFuzzer target: frame samples (HullFrame and Contour) as the aggregator receives them.
#include "tests/fuzz/fuzz_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)silnet::fuzz::FuzzFrameSample({data, size});
  return 0;
}

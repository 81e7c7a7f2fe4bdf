// libFuzzer target: session log files as the aggregator and the tools read them.
#include "tests/fuzz/fuzz_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)silnet::fuzz::FuzzSessionLog({data, size});
  return 0;
}

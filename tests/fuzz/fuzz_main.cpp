// One libFuzzer program per target: NUDGE_FUZZ_TARGET names the function (tests/fuzz/CMakeLists.txt).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return nudge::fuzz::NUDGE_FUZZ_TARGET(data, size);
}

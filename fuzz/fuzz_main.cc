// libFuzzer entry point; fuzz/CMakeLists.txt builds one binary per harness, naming it with
// MAPLESS_FUZZ_HARNESS.
#include <cstddef>
#include <cstdint>
#include <string>

#include "harnesses.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mapless::fuzz::MAPLESS_FUZZ_HARNESS(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}

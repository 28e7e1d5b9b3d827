// Every kept fuzz input (fuzz/corpus/<target>/: the seeds, and every input that once crashed a
// parser) through its harness in the ordinary test suite: no crash, no exception but InputError.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "harnesses.h"
#include "mapless/io/atomic_file.h"

namespace mapless::fuzz {
namespace {

TEST(FuzzRegressions, EveryKeptInputIsParsedOrRefusedWithAnInputError) {
  const std::filesystem::path root = std::filesystem::path(MAPLESS_SOURCE_DIR) / "fuzz" / "corpus";
  for (const NamedHarness& h : Harnesses()) {
    const std::filesystem::path dir = root / h.name;
    ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir << " is missing";
    int inputs = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      if (!entry.is_regular_file()) continue;
      SCOPED_TRACE(entry.path().string());
      const std::string bytes = io::ReadFile(entry.path().string(), 1 << 26);
      EXPECT_NO_THROW(h.run(bytes));
      ++inputs;
    }
    EXPECT_GT(inputs, 0) << h.name << ": no kept inputs in " << dir;
  }
}

}  // namespace
}  // namespace mapless::fuzz

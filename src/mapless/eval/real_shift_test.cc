// `eval shift` (issue 66): both dataset layouts and the baselines in the same run. The acceptance
// on all 660 pairs of ../shared/data/stromovka_sessions is
// EstimateShift.StromovkaAllSessionPairs... (features_test); the baselines' figures there come from
// `mapless eval shift` (docs/results.md).
#include "mapless/eval/real_shift.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "mapless/core/check.h"

namespace mapless::eval {
namespace {

namespace fs = std::filesystem;
const std::string kBundled = std::string(MAPLESS_SOURCE_DIR) + "/tests/data/stromovka";

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

const ShiftMethodFigures& Method(const ShiftEvalFigures& f, const std::string& name) {
  for (const auto& m : f.methods) {
    if (m.method == name) return m;
  }
  throw std::runtime_error("no method " + name);
}

TEST(EvalShift, TheSessionsLayoutGivesEveryOrderedPairOfAPlace) {
  const ShiftDataset data = LoadShiftDataset(kBundled);
  EXPECT_EQ(data.layout, "sessions");
  EXPECT_EQ(data.images.size(), 6u);
  ASSERT_EQ(data.pairs.size(), 12u);  // two places, three sessions: 3 * 2 ordered pairs each
  // Place 1, session 06 as reference, 12 as current: 40.5 - (-32.0).
  bool found = false;
  for (const auto& p : data.pairs) {
    if (EndsWith(data.images[static_cast<std::size_t>(p.reference)], "0601.png") &&
        EndsWith(data.images[static_cast<std::size_t>(p.current)], "1201.png")) {
      EXPECT_DOUBLE_EQ(p.truth_dx_px, 72.5);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  const ShiftEvalFigures f = EvalShift(data, {});
  ASSERT_EQ(f.methods.size(), 3u);
  EXPECT_EQ(f.methods[0].method, "mapless");
  for (const auto& m : f.methods) {
    EXPECT_EQ(m.pairs, 12) << m.method;
    EXPECT_GT(m.extract_ms, 0.0) << m.method;
  }
  EXPECT_GE(Method(f, "mapless").within, 10);  // the full 660 pairs: features_test
  EXPECT_GE(Method(f, "mapless").within, Method(f, "orb").within);
}

TEST(EvalShift, TheTwoFolderLayoutReadsBothDirectionsAndNamesABadLine) {
  const fs::path dir = fs::temp_directory_path() / ("mapless_shift_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "summer");
  fs::create_directories(dir / "winter");
  fs::copy_file(kBundled + "/0101.png", dir / "summer" / "a.png");
  fs::copy_file(kBundled + "/1201.png", dir / "winter" / "a.png");
  std::ofstream(dir / "dx.txt") << "# name dx = x_winter - x_summer\na.png 40.5\n";
  const ShiftDataset data = LoadShiftDataset(dir.string());
  EXPECT_EQ(data.layout, "two folders");
  ASSERT_EQ(data.pairs.size(), 2u);
  EXPECT_DOUBLE_EQ(data.pairs[0].truth_dx_px, 40.5);
  EXPECT_DOUBLE_EQ(data.pairs[1].truth_dx_px, -40.5);
  const ShiftEvalFigures f = EvalShift(data, {});
  EXPECT_EQ(Method(f, "mapless").within, 2);
  std::ofstream(dir / "dx.txt") << "a.png 40.5\nb.png 3\n";
  try {
    LoadShiftDataset(dir.string());
    ADD_FAILURE() << "a missing image was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dx.txt:2"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mapless::eval

#include "mapless/localization/sequence.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "mapless/io/image_file.h"

namespace mapless::localization {
namespace {

namespace fs = std::filesystem;

// Nordland (summer database, winter queries), the first 1200 places: same file name = same place.
// Present in ../shared/data only (not copied: 2400 files); the test skips without it.
struct Nordland {
  std::vector<cv::Mat> summer;
  std::vector<cv::Mat> winter;
};

bool LoadNordland(Nordland* data) {
  const fs::path root = fs::path(MAPLESS_SOURCE_DIR) / ".." / "shared" / "data" / "nordland_64x32";
  if (!fs::is_directory(root / "summer")) return false;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(root / "summer"))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  for (const std::string& n : names) {
    data->summer.push_back(io::ReadImage((root / "summer" / n).string(), cv::IMREAD_GRAYSCALE));
    data->winter.push_back(io::ReadImage((root / "winter" / n).string(), cv::IMREAD_GRAYSCALE));
  }
  return !data->summer.empty();
}

double FractionWithin(const std::vector<QueryLocalization>& r, int tolerance) {
  int ok = 0;
  for (std::size_t i = 0; i < r.size(); ++i)
    ok += std::abs(r[i].index - static_cast<int>(i)) <= tolerance;
  return static_cast<double>(ok) / static_cast<double>(r.size());
}

TEST(LocalizeSequence, NordlandWinterOnSummerMarkovBeatsNearestProjection) {
  Nordland data;
  if (!LoadNordland(&data)) GTEST_SKIP() << "../shared/data/nordland_64x32 not present";
  SequenceLocalizationOptions options;
  const appearance::Eigenspace route = BuildRouteEigenspace(data.summer, options);
  options.method = SequenceMethod::kNearest;
  const double nn = FractionWithin(LocalizeSequence(route, data.winter, options), 5);
  options.method = SequenceMethod::kMarkov;
  const double markov = FractionWithin(LocalizeSequence(route, data.winter, options), 5);
  std::printf("Nordland winter on summer, within +-5 places: nn %.3f, markov %.3f\n", nn, markov);
  RecordProperty("nn_within_5", std::to_string(nn));
  RecordProperty("markov_within_5", std::to_string(markov));
  EXPECT_GT(markov, 0.8);
  EXPECT_GT(markov, nn + 0.5);
}

}  // namespace
}  // namespace mapless::localization

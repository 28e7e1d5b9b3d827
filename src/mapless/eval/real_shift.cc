#include "mapless/eval/real_shift.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/eval/experiences.h"
#include "mapless/eval/real_common.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"

namespace mapless::eval {
namespace {

constexpr std::size_t kMaxListBytes = 1 << 20;
constexpr int kBaselineKeypoints = 1600;
constexpr double kBaselineBinPx = 10.0;

ShiftDataset FromSessions(const std::string& dir) {
  const SessionsDataset sessions = LoadSessionsDataset(dir);
  ShiftDataset data;
  data.dir = dir;
  data.layout = "sessions";
  for (const auto& [place, visits] : sessions.places) {
    const int first = static_cast<int>(data.images.size());
    for (const auto& v : visits) data.images.push_back(v.image);
    for (std::size_t a = 0; a < visits.size(); ++a) {
      for (std::size_t b = 0; b < visits.size(); ++b) {
        if (a == b) continue;
        data.pairs.push_back({first + static_cast<int>(a), first + static_cast<int>(b),
                              visits[b].offset_px - visits[a].offset_px});
      }
    }
  }
  return data;
}

ShiftDataset FromTwoFolders(const std::string& dir) {
  const std::string file = dir + "/dx.txt";
  MAPLESS_CHECK(std::filesystem::is_regular_file(file),
                dir << ": neither offsets.txt (sessions) nor dx.txt (summer/ winter/) in it");
  std::istringstream lines(io::ReadFile(file, kMaxListBytes));
  ShiftDataset data;
  data.dir = dir;
  data.layout = "two folders";
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name, rest;
    double dx = 0.0;
    const bool parsed = static_cast<bool>(fields >> name >> dx) && !(fields >> rest);
    MAPLESS_CHECK(parsed && std::isfinite(dx) && std::abs(dx) <= 1e5 &&
                      name.find('/') == std::string::npos && name != "." && name != "..",
                  file << ":" << number << ": expected \"NAME dx_px\" (a file name in summer/ "
                       << "and winter/, a finite offset), got \"" << line << "\"");
    const int first = static_cast<int>(data.images.size());
    for (const char* season : {"summer", "winter"}) {
      const std::string image = dir + "/" + season + "/" + name;
      MAPLESS_CHECK(std::filesystem::is_regular_file(image),
                    file << ":" << number << ": no image " << image);
      data.images.push_back(image);
    }
    data.pairs.push_back({first, first + 1, dx});
    data.pairs.push_back({first + 1, first, -dx});
  }
  MAPLESS_CHECK(!data.pairs.empty(), file << ": no image listed");
  return data;
}

using Extract = std::function<features::Features(const cv::Mat&)>;

ShiftMethodFigures Evaluate(const std::string& name, const std::vector<cv::Mat>& images,
                            const ShiftDataset& data, const Extract& extract,
                            const features::ShiftOptions& shift, double tolerance_px) {
  ShiftMethodFigures out;
  out.method = name;
  std::vector<features::Features> described;
  std::vector<double> extract_ms, match_ms;
  for (const cv::Mat& image : images) {
    const auto start = std::chrono::steady_clock::now();
    described.push_back(extract(image));
    extract_ms.push_back(MsSince(start));
  }
  for (const ShiftPair& pair : data.pairs) {
    const auto start = std::chrono::steady_clock::now();
    const features::ShiftEstimate e =
        features::EstimateShift(described[static_cast<std::size_t>(pair.reference)],
                                described[static_cast<std::size_t>(pair.current)], shift);
    match_ms.push_back(MsSince(start));
    ++out.pairs;
    out.not_ok += e.ok ? 0 : 1;
    out.within += e.ok && std::abs(e.dx_px - pair.truth_dx_px) <= tolerance_px ? 1 : 0;
  }
  out.fraction = out.pairs > 0 ? static_cast<double>(out.within) / out.pairs : 0.0;
  out.extract_ms = Median(extract_ms);
  out.match_ms = Median(match_ms);
  out.pair_ms = 2.0 * out.extract_ms + out.match_ms;
  return out;
}

// The baselines' matching and vote: cross-checked, no ratio test, dx alone.
features::ShiftOptions BaselineVote() {
  features::ShiftOptions o;
  o.matching.ratio = 1.0;
  o.matching.mutual = true;
  o.bin_px = kBaselineBinPx;
  o.bin_dy_px = 0.0;
  return o;
}

features::Features StockOrb(const cv::Mat& image) {
  static thread_local const cv::Ptr<cv::ORB> orb = cv::ORB::create(kBaselineKeypoints);
  features::Features f;
  orb->detectAndCompute(image, cv::noArray(), f.keypoints, f.descriptors);
  f.binary = true;
  return f;
}

features::Features StockFastSift(const cv::Mat& image) {
  static thread_local const cv::Ptr<cv::FastFeatureDetector> fast =
      cv::FastFeatureDetector::create();
  static thread_local const cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  features::Features f;
  fast->detect(image, f.keypoints);
  cv::KeyPointsFilter::retainBest(f.keypoints, kBaselineKeypoints);
  sift->compute(image, f.keypoints, f.descriptors);
  f.binary = false;
  return f;
}

}  // namespace

ShiftDataset LoadShiftDataset(const std::string& dir) {
  MAPLESS_CHECK(std::filesystem::is_directory(dir), dir << ": not a directory");
  return std::filesystem::exists(dir + "/offsets.txt") ? FromSessions(dir) : FromTwoFolders(dir);
}

ShiftEvalFigures EvalShift(const ShiftDataset& data, const ShiftEvalOptions& options) {
  options.shift.Validate();
  MAPLESS_CHECK(options.tolerance_px > 0.0 && std::isfinite(options.tolerance_px),
                "tolerance " << options.tolerance_px << " px: must be > 0");
  // Every image is read and checked before any work: same size as the first, grey.
  std::vector<cv::Mat> images;
  double pixels = 0.0;
  for (const std::string& path : data.images) {
    images.push_back(io::ReadImage(path, cv::IMREAD_GRAYSCALE, 16));
    pixels += static_cast<double>(images.back().total());
    MAPLESS_CHECK(pixels <= kMaxHeldPixels, data.dir << ": its images hold more than "
                                                     << kMaxHeldPixels / 1e6
                                                     << " megapixels in all (at " << path
                                                     << "); use fewer or smaller images");
    if (images.size() > 1) io::RequireSameSize(images.back(), path, images.front(), data.images[0]);
  }
  ShiftEvalFigures out;
  out.images = static_cast<int>(images.size());
  out.pairs = static_cast<int>(data.pairs.size());
  out.tolerance_px = options.tolerance_px;
  const features::FeatureExtractor extractor(options.shift.features);
  out.methods.push_back(Evaluate(
      "mapless", images, data, [&](const cv::Mat& m) { return extractor.Extract(m); },
      options.shift, options.tolerance_px));
  if (options.baselines) {
    out.methods.push_back(
        Evaluate("orb", images, data, StockOrb, BaselineVote(), options.tolerance_px));
    out.methods.push_back(
        Evaluate("fast_sift", images, data, StockFastSift, BaselineVote(), options.tolerance_px));
  }
  return out;
}

}  // namespace mapless::eval

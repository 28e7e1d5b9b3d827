#include "mapless/eval/real_localize.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "mapless/core/check.h"
#include "mapless/eval/real_common.h"
#include "mapless/io/image_file.h"
#include "mapless/localization/sequence.h"

namespace mapless::eval {
namespace {

struct Folder {
  std::vector<std::string> names;
  std::vector<cv::Mat> images;
};

Folder ReadFolder(const std::string& dir, const std::string& option) {
  Folder folder;
  folder.names = ImageNamesIn(dir, option);
  double pixels = 0.0;
  for (const std::string& name : folder.names) {
    folder.images.push_back(io::ReadImage(dir + "/" + name, cv::IMREAD_GRAYSCALE, 4));
    pixels += static_cast<double>(folder.images.back().total());
    MAPLESS_CHECK(pixels <= kMaxHeldPixels,
                  option << " " << dir << ": more than " << kMaxHeldPixels / 1e6
                         << " megapixels in all; use fewer or smaller images");
  }
  return folder;
}

// Fills the within fractions from the estimates; `confidence` empty: no recall figure.
LocalizeMethodFigures Score(const std::string& method, const std::vector<int>& estimate,
                            const std::vector<int>& truth, const std::vector<double>& confidence,
                            double query_ms) {
  LocalizeMethodFigures f;
  f.method = method;
  f.queries = static_cast<int>(estimate.size());
  f.query_ms = query_ms;
  int w0 = 0, w1 = 0, w5 = 0, w10 = 0;
  std::vector<std::pair<double, bool>> scored;
  for (std::size_t q = 0; q < estimate.size(); ++q) {
    const int error = std::abs(estimate[q] - truth[q]);
    w0 += error == 0;
    w1 += error <= 1;
    w5 += error <= 5;
    w10 += error <= 10;
    if (!confidence.empty()) scored.emplace_back(confidence[q], error <= 5);
  }
  const double n = std::max(1, f.queries);
  f.within0 = w0 / n;
  f.within1 = w1 / n;
  f.within5 = w5 / n;
  f.within10 = w10 / n;
  if (!confidence.empty()) f.recall_at_full_precision = RecallAtFullPrecision(scored);
  return f;
}

}  // namespace

double RecallAtFullPrecision(std::vector<std::pair<double, bool>> scored) {
  if (scored.empty()) return 0.0;
  // Highest confidence first; among equal confidences the wrong ones first (no credit for ties).
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  std::size_t accepted = 0;
  while (accepted < scored.size() && scored[accepted].second) ++accepted;
  // A threshold cannot split equal confidences: back off to the last change of confidence.
  while (accepted > 0 && accepted < scored.size() &&
         scored[accepted - 1].first == scored[accepted].first) {
    --accepted;
  }
  return static_cast<double>(accepted) / static_cast<double>(scored.size());
}

LocalizeEvalFigures EvalLocalize(const std::string& database_dir, const std::string& query_dir,
                                 const LocalizeEvalOptions& options) {
  options.filter.Validate();
  const Folder database = ReadFolder(database_dir, "--database");
  const Folder query = ReadFolder(query_dir, "--query");
  MAPLESS_CHECK(database.images.size() >= 2,
                "--database " << database_dir << ": at least 2 images are needed");
  std::map<std::string, int> place;
  for (std::size_t i = 0; i < database.names.size(); ++i)
    place[database.names[i]] = static_cast<int>(i);
  std::vector<int> truth;
  for (const std::string& name : query.names) {
    const auto it = place.find(name);
    MAPLESS_CHECK(it != place.end(), "--query " << query_dir << "/" << name
                                                << ": no database image of that name (the truth)");
    truth.push_back(it->second);
  }
  LocalizeEvalFigures out;
  out.database = static_cast<int>(database.images.size());
  out.queries = static_cast<int>(query.images.size());
  cv::Mat route;
  for (const cv::Mat& image : database.images)
    route.push_back(localization::SequenceDescriptor(image, options.filter));
  {  // mapless: the sequence filter
    localization::SequenceFilter filter(route, options.filter);
    std::vector<int> estimate;
    std::vector<double> confidence, ms;
    for (const cv::Mat& image : query.images) {
      const auto start = std::chrono::steady_clock::now();
      const localization::SequenceEstimate e =
          filter.Update(localization::SequenceDescriptor(image, options.filter));
      ms.push_back(MsSince(start));
      estimate.push_back(e.index);
      confidence.push_back(e.confidence);
    }
    out.methods.push_back(Score("mapless", estimate, truth, confidence, Median(ms)));
  }
  if (!options.baselines) return out;
  {  // SeqSLAM-style: the same descriptors and differences, straight sequences over past queries
    std::vector<std::vector<double>> differences;
    std::vector<double> ms;
    for (const cv::Mat& image : query.images) {
      const auto start = std::chrono::steady_clock::now();
      differences.push_back(localization::EnhancedDifferences(
          route, localization::SequenceDescriptor(image, options.filter),
          options.filter.contrast_window));
      ms.push_back(MsSince(start));
    }
    const auto start = std::chrono::steady_clock::now();
    const std::vector<int> estimate =
        localization::SeqSlamPastOnly(differences, options.seqslam_length);
    const double search_ms = MsSince(start) / std::max<std::size_t>(1, query.images.size());
    out.methods.push_back(Score("seqslam", estimate, truth, {}, Median(ms) + search_ms));
  }
  // The paper's Markov localization and nearest projection on an incremental-PCA eigenspace.
  for (const auto method :
       {localization::SequenceMethod::kMarkov, localization::SequenceMethod::kNearest}) {
    localization::SequenceLocalizationOptions o;
    o.method = method;
    o.image.width = options.filter.width;
    o.image.height = options.filter.height;
    o.pca.max_dimensions = options.pca_dimensions;
    const appearance::Eigenspace eigenspace =
        localization::BuildRouteEigenspace(database.images, o);
    const auto start = std::chrono::steady_clock::now();
    const auto results = localization::LocalizeSequence(eigenspace, query.images, o);
    const double ms = MsSince(start) / std::max<std::size_t>(1, query.images.size());
    std::vector<int> estimate;
    std::vector<double> confidence;
    for (const auto& r : results) {
      estimate.push_back(r.index);
      confidence.push_back(r.probability);
    }
    out.methods.push_back(
        Score(method == localization::SequenceMethod::kMarkov ? "markov_pca" : "nearest_pca",
              estimate, truth, confidence, ms));
  }
  return out;
}

}  // namespace mapless::eval

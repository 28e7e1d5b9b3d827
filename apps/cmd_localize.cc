// `mapless localize --database DIR --query DIR [--method nn|markov] --json`: appearance-based
// localization of each query image on the route the database images form (file-name order), one
// JSON object per query: {"query": name, "index": i, "probability": p}.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "mapless/core/check.h"
#include "mapless/io/frame_source.h"
#include "mapless/localization/sequence.h"
#include "mapless/localization/sequence_filter.h"
#include "mapless/recording/playback.h"

namespace mapless::app {
namespace {

// All images of a folder are kept while the eigenspace is built: 512 megapixels of grey at most.
constexpr double kMaxFolderPixels = 512e6;

struct Folder {
  std::vector<cv::Mat> images;
  std::vector<std::string> names;
};

// The images of a folder, a recording (.mcap, .bag) or a video, in order.
Folder ReadFolder(const std::string& dir, const std::string& option,
                  const recording::PlaybackOptions& playback) {
  MAPLESS_CHECK(std::filesystem::is_directory(dir) || std::filesystem::is_regular_file(dir),
                option << " " << dir << ": not a folder of images, a recording or a video");
  Folder folder;
  recording::PlaybackOptions once = playback;
  once.loop = false;  // every image is kept
  const std::unique_ptr<io::FrameSource> source = recording::OpenSource(dir, once);
  io::Frame frame;
  double pixels = 0.0;
  while (source->Next(&frame)) {
    pixels += static_cast<double>(frame.image.total());
    MAPLESS_CHECK(pixels <= kMaxFolderPixels, option << " " << dir << ": its images hold more than "
                                                     << kMaxFolderPixels / 1e6
                                                     << " megapixels in all (frame " << frame.name
                                                     << "); use fewer or smaller images");
    folder.images.push_back(frame.image.clone());
    folder.names.push_back(frame.name);
  }
  MAPLESS_CHECK(!folder.images.empty(), option << " " << dir << ": no images in it");
  return folder;
}

void PrintQuery(const std::string& name, int index, double probability) {
  nlohmann::ordered_json j;
  j["query"] = name;
  j["index"] = index;
  j["probability"] = probability;
  std::cout << j.dump() << "\n";
}

}  // namespace

void AddLocalizeCommand(CLI::App* app) {
  struct Args {
    std::string database;
    std::string query;
    std::string method = "sequence";
    std::string pca = "incremental";
    bool json = false;
    int width = 64;
    int height = 64;
    int dimensions = 16;
    double advance = 1.0;
    double advance_sigma = 0.2;
    double start_sigma = localization::SequenceFilterOptions{}.start_sigma;
    recording::PlaybackOptions playback;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "localize", "Localize query images on the route formed by database images (incremental PCA)");
  cmd->add_option("--database", args->database,
                  "Route images: a folder (file-name order), a recording (.mcap, .bag) or a video")
      ->required();
  cmd->add_option("--query", args->query,
                  "Query images (a traversal of the same route): a folder, a recording or a video")
      ->required();
  cmd->add_option("--topic", args->playback.topic,
                  "Recordings: the camera topic (default: the only one)");
  cmd->add_option("--start", args->playback.start_s, "Begin this many seconds into each source")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 1e9));
  cmd->add_option("--localizer", args->method,
                  "sequence (the sequence filter across seasons), markov (the paper's) or nn "
                  "(nearest projection)")
      ->capture_default_str();
  AddOldName(cmd, "--method", "--localizer", &args->method);
  cmd->add_option("--pca", args->pca, "incremental or batch")->capture_default_str();
  cmd->add_option("--dimensions", args->dimensions, "Eigenspace dimensions K")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--width", args->width, "Low-resolution image width, px")
      ->capture_default_str()
      ->check(CLI::Range(8, 1024));
  cmd->add_option("--height", args->height, "Low-resolution image height, px")
      ->capture_default_str()
      ->check(CLI::Range(8, 1024));
  cmd->add_option("--advance", args->advance, "Motion model: database images per query image")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 1000.0));
  CLI::Option* sigma = cmd->add_option("--advance-sigma", args->advance_sigma,
                                       "Motion model: its standard deviation per query, database "
                                       "images (sequence: 0.5 unless given)");
  sigma->capture_default_str()->check(FiniteIn(0.01, 1000.0));
  cmd->add_option("--start-sigma", args->start_sigma,
                  "sequence: the queries start within about this many database images of the "
                  "first (0: anywhere)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 1e6));
  cmd->add_flag("--json", args->json, "One JSON object per query (the only output format)");
  cmd->callback([args, sigma] {
    localization::SequenceLocalizationOptions options;
    options.method = localization::ParseSequenceMethod(args->method);
    MAPLESS_CHECK(args->pca == "incremental" || args->pca == "batch",
                  "--pca " << args->pca << ": use incremental or batch");
    options.incremental_pca = args->pca == "incremental";
    options.image.width = args->width;
    options.image.height = args->height;
    options.pca.max_dimensions = args->dimensions;
    options.advance_per_query = args->advance;
    options.advance_sigma = args->advance_sigma;
    options.Validate();
    const Folder database = ReadFolder(args->database, "--database", args->playback);
    const Folder query = ReadFolder(args->query, "--query", args->playback);
    if (options.method == localization::SequenceMethod::kSequenceFilter) {
      localization::SequenceFilterOptions filter;
      filter.advance = args->advance;
      if (sigma->count() > 0) filter.advance_sigma = args->advance_sigma;
      filter.start_sigma = args->start_sigma;
      const auto results = localization::FilterSequence(database.images, query.images, filter);
      for (std::size_t i = 0; i < results.size(); ++i)
        PrintQuery(query.names[i], results[i].index, results[i].confidence);
      return;
    }
    const appearance::Eigenspace route =
        localization::BuildRouteEigenspace(database.images, options);
    spdlog::info("localize: {} route images, eigenspace of {} dimensions ({} PCA); {} queries ({})",
                 database.images.size(), route.dimensions(), args->pca, query.images.size(),
                 args->method);
    const auto results = localization::LocalizeSequence(route, query.images, options);
    for (std::size_t i = 0; i < results.size(); ++i)
      PrintQuery(query.names[i], results[i].index, results[i].probability);
  });
}

}  // namespace mapless::app

#include "mapless/route/appearance_store.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/io/limits.h"
#include "mapless/route/manifest_text.h"
#include "mapless/route/route_store.h"

namespace mapless::route {

namespace fs = std::filesystem;

namespace {

constexpr const char* kManifest = "appearance.json";

std::string ImageFile(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "images/%06d.png", index);
  return name;
}

// An image's manifest entry, with its learned views when it has any (version 2).
nlohmann::json EntryJson(std::size_t index, const StoredAppearanceImage& e) {
  nlohmann::json j = {{"index", index},
                      {"distance_m", e.distance_m},
                      {"x_m", e.odometry.x_m},
                      {"y_m", e.odometry.y_m},
                      {"theta_rad", e.odometry.theta_rad},
                      {"file", ImageFile(static_cast<int>(index))}};
  if (!e.views.empty()) {
    nlohmann::json views = nlohmann::json::array();
    for (const StoredAppearanceView& v : e.views) {
      views.push_back({{"file", v.file},
                       {"offset_px", v.offset_px},
                       {"learned_at", v.learned_at},
                       {"last_used", v.last_used}});
    }
    j["views"] = views;
  }
  return j;
}

nlohmann::json HeadJson(const StoredAppearanceRoute& header, bool with_views) {
  nlohmann::json j;
  j["format"] = "mapless-appearance-route";
  j["version"] = with_views ? kAppearanceRouteViewsFormatVersion : kAppearanceRouteFormatVersion;
  if (with_views) j["visits"] = header.visits;
  j["image_width"] = header.image_width;
  j["image_height"] = header.image_height;
  j["low_width"] = header.low_width;
  j["low_height"] = header.low_height;
  j["complete"] = header.complete;
  return j;
}

bool HasViews(const std::vector<StoredAppearanceImage>& images) {
  for (const StoredAppearanceImage& e : images)
    if (!e.views.empty()) return true;
  return false;
}

}  // namespace

int StoredAppearanceRoute::views() const {
  int n = 0;
  for (const StoredAppearanceImage& e : images) n += static_cast<int>(e.views.size());
  return n;
}

std::string AppearanceViewFile(int index, int visit) {
  char name[48];
  std::snprintf(name, sizeof(name), "views/%06d-visit-%04d.png", index, visit);
  return name;
}

AppearanceRouteWriter::AppearanceRouteWriter(std::string dir, int image_width, int image_height,
                                             int low_width, int low_height)
    : dir_(std::move(dir)) {
  header_.image_width = image_width;
  header_.image_height = image_height;
  header_.low_width = low_width;
  header_.low_height = low_height;
  MAPLESS_CHECK(!fs::exists(fs::path(dir_) / kManifest),
                dir_ << ": already holds an appearance route");
  fs::create_directories(fs::path(dir_) / "images");
  WriteManifest();
}

std::unique_ptr<AppearanceRouteWriter> AppearanceRouteWriter::Reopen(const std::string& dir) {
  const std::string manifest = (fs::path(dir) / kManifest).string();
  std::unique_ptr<AppearanceRouteWriter> writer(new AppearanceRouteWriter());
  writer->dir_ = dir;
  writer->header_ =
      ParseAppearanceManifest(io::ReadFile(manifest, io::kMaxManifestBytes), manifest, nullptr);
  writer->entries_ = std::move(writer->header_.images);
  writer->header_.images.clear();
  return writer;
}

void AppearanceRouteWriter::Append(const StoredAppearanceImage& image) {
  MAPLESS_CHECK(image.low.type() == CV_8UC1 && image.low.cols == header_.low_width &&
                    image.low.rows == header_.low_height,
                "AppearanceRouteWriter: a route image must be 8-bit " << header_.low_width << "x"
                                                                      << header_.low_height);
  AppendEncoded(image, io::EncodeImage(image.low, ".png", dir_));
  Flush();
}

void AppearanceRouteWriter::AppendEncoded(const StoredAppearanceImage& entry,
                                          std::string_view png) {
  MAPLESS_CHECK(!header_.complete, "AppearanceRouteWriter: an image after the route's end");
  const std::string path = (fs::path(dir_) / ImageFile(images())).string();
  io::WriteNewFile(path, png);
  pending_.push_back(path);
  StoredAppearanceImage e = entry;
  e.low = cv::Mat();
  entries_.push_back(e);
}

void AppearanceRouteWriter::Flush() {
  io::SyncFiles(pending_);
  pending_.clear();
  WriteManifest();
}

void AppearanceRouteWriter::Finish() {
  header_.complete = true;
  Flush();
}

void AppearanceRouteWriter::WriteManifest() const {
  // A reopened route keeps the views a follower learned into it (version 2).
  for (std::size_t i = entry_text_.size(); i < entries_.size(); ++i)
    entry_text_.push_back(EntryText(EntryJson(i, entries_[i])));
  io::WriteFileAtomic((fs::path(dir_) / kManifest).string(),
                      ManifestText(HeadJson(header_, HasViews(entries_)), "images", entry_text_));
}

void SaveAppearanceViews(const std::string& dir, StoredAppearanceRoute* route) {
  MAPLESS_CHECK(route->visits >= 0, "SaveAppearanceViews: visits = " << route->visits);
  std::vector<std::string> written;
  std::set<std::string> listed;
  for (std::size_t i = 0; i < route->images.size(); ++i) {
    StoredAppearanceImage& image = route->images[i];
    MAPLESS_CHECK(image.views.size() <= static_cast<std::size_t>(kMaxAppearanceViewsPerImage),
                  "SaveAppearanceViews: image " << i << " has " << image.views.size() << " views");
    for (StoredAppearanceView& v : image.views) {
      if (v.file.empty()) {
        MAPLESS_CHECK(v.low.type() == CV_8UC1 && v.low.cols == route->low_width &&
                          v.low.rows == route->low_height,
                      "SaveAppearanceViews: a view must be 8-bit " << route->low_width << "x"
                                                                   << route->low_height);
        v.file = AppearanceViewFile(static_cast<int>(i), v.learned_at);
        const std::string path = (fs::path(dir) / v.file).string();
        fs::create_directories(fs::path(path).parent_path());
        io::WriteFileAtomic(path, io::EncodeImage(v.low, ".png", dir), false);
        written.push_back(path);
      }
      listed.insert(v.file);
    }
  }
  io::SyncFiles(written);
  std::vector<std::string> entries;
  for (std::size_t i = 0; i < route->images.size(); ++i)
    entries.push_back(EntryText(EntryJson(i, route->images[i])));
  io::WriteFileAtomic((fs::path(dir) / kManifest).string(),
                      ManifestText(HeadJson(*route, true), "images", entries));
  // Pruned views: their files, now listed nowhere.
  const fs::path views = fs::path(dir) / "views";
  if (!fs::is_directory(views)) return;
  for (const auto& file : fs::directory_iterator(views)) {
    const std::string name = "views/" + file.path().filename().string();
    if (listed.count(name) == 0 && IsViewFileName(file.path().filename().string(), ".png") &&
        file.is_regular_file() && !file.is_symlink()) {
      std::error_code ignored;
      fs::remove(file.path(), ignored);
    }
  }
}

std::string AppearanceImageFile(int index) { return ImageFile(index); }

std::string AppearanceEntryJson(const StoredAppearanceImage& image) {
  nlohmann::json j;
  j["distance_m"] = image.distance_m;
  j["x_m"] = image.odometry.x_m;
  j["y_m"] = image.odometry.y_m;
  j["theta_rad"] = image.odometry.theta_rad;
  return j.dump();
}

StoredAppearanceImage ParseAppearanceEntry(const std::string& text, const std::string& name) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  MAPLESS_CHECK(!j.is_discarded() && j.is_object(), name << ": not a JSON object");
  auto number = [&](const char* key) {
    MAPLESS_CHECK(j.contains(key) && j[key].is_number(),
                  name << ": " << key << ": missing or not a number");
    const double v = j[key].get<double>();
    MAPLESS_CHECK(std::isfinite(v) && std::abs(v) <= 1e7,
                  name << ": " << key << " = " << v << ": out of range");
    return v;
  };
  StoredAppearanceImage image;
  image.distance_m = number("distance_m");
  MAPLESS_CHECK(image.distance_m >= 0.0, name << ": distance_m is negative");
  image.odometry = Pose2{number("x_m"), number("y_m"), number("theta_rad")};
  return image;
}

namespace {

// An image entry's learned views: at most kMaxAppearanceViewsPerImage, each file the one its
// image and visit name, visits within the route's, offsets within the image's reach.
std::vector<StoredAppearanceView> ParseAppearanceViews(const nlohmann::json& list, int index,
                                                       int visits, const std::string& where) {
  MAPLESS_CHECK(list.is_array(), where << "views: not a list");
  MAPLESS_CHECK(
      list.size() <= static_cast<std::size_t>(kMaxAppearanceViewsPerImage),
      where << "views: " << list.size() << " (at most " << kMaxAppearanceViewsPerImage << ")");
  std::vector<StoredAppearanceView> views;
  std::set<int> visits_seen;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const nlohmann::json& v = list[k];
    const std::string at = where + "views[" + std::to_string(k) + "].";
    MAPLESS_CHECK(v.is_object(), at << ": not an object");
    auto whole = [&](const char* key) {
      MAPLESS_CHECK(v.contains(key) && v[key].is_number(),
                    at << key << ": missing or not a number");
      const double x = v[key].get<double>();
      MAPLESS_CHECK(
          std::isfinite(x) && x == std::floor(x) && x >= 1 && x <= visits,
          at << key << " = " << v[key].dump() << "; must be a visit in [1, " << visits << "]");
      return static_cast<int>(x);
    };
    StoredAppearanceView view;
    view.learned_at = whole("learned_at");
    view.last_used = whole("last_used");
    MAPLESS_CHECK(view.last_used >= view.learned_at,
                  at << "last_used: before the visit that learned it");
    MAPLESS_CHECK(visits_seen.insert(view.learned_at).second,
                  at << "learned_at: two views of one image learned at visit " << view.learned_at);
    MAPLESS_CHECK(v.contains("offset_px") && v["offset_px"].is_number() &&
                      std::isfinite(v["offset_px"].get<double>()) &&
                      std::abs(v["offset_px"].get<double>()) <= io::kMaxImageSide,
                  at << "offset_px: missing or not a number of pixels within the image");
    view.offset_px = v["offset_px"].get<double>();
    view.file = AppearanceViewFile(index, view.learned_at);
    MAPLESS_CHECK(
        v.contains("file") && v["file"].is_string() && v["file"].get<std::string>() == view.file,
        at << "file: must be " << view.file);
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace

StoredAppearanceRoute ParseAppearanceManifest(const std::string& text, const std::string& name,
                                              std::vector<std::string>* files) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  MAPLESS_CHECK(!j.is_discarded() && j.is_object(), name << ": not a JSON object");
  auto number = [&](const nlohmann::json& o, const char* key, const std::string& where) {
    MAPLESS_CHECK(o.contains(key) && o[key].is_number(),
                  name << ": " << where << key << ": missing or not a number");
    const double v = o[key].get<double>();
    MAPLESS_CHECK(std::isfinite(v) && std::abs(v) <= 1e7,
                  name << ": " << where << key << " = " << v << ": out of range");
    return v;
  };
  auto integer = [&](const char* key, int lo, int hi) {
    const double v = number(j, key, "");
    MAPLESS_CHECK(v == std::floor(v) && v >= lo && v <= hi, name << ": " << key << " = " << v
                                                                 << "; must be a whole number in ["
                                                                 << lo << ", " << hi << "]");
    return static_cast<int>(v);
  };
  MAPLESS_CHECK(j.contains("format") && j["format"] == "mapless-appearance-route",
                name << ": format: not a mapless appearance route");
  const int version = integer("version", 0, 1000);
  MAPLESS_CHECK(
      version == kAppearanceRouteFormatVersion || version == kAppearanceRouteViewsFormatVersion,
      name << ": version " << j["version"].dump() << " (this mapless reads versions "
           << kAppearanceRouteFormatVersion << " and " << kAppearanceRouteViewsFormatVersion
           << ")");
  StoredAppearanceRoute route;
  if (version == kAppearanceRouteViewsFormatVersion)
    route.visits = integer("visits", 0, kMaxRouteVisits);
  route.image_width = integer("image_width", 16, io::kMaxImageSide);
  route.image_height = integer("image_height", 16, io::kMaxImageSide);
  MAPLESS_CHECK(std::int64_t{route.image_width} * route.image_height <= io::kMaxImagePixels,
                name << ": image size " << route.image_width << "x" << route.image_height
                     << ": at most " << io::kMaxImagePixels / 1'000'000 << " megapixels");
  route.low_width = integer("low_width", 8, 1024);
  route.low_height = integer("low_height", 8, 1024);
  MAPLESS_CHECK(j.contains("complete") && j["complete"].is_boolean(),
                name << ": complete: missing or not true/false");
  route.complete = j["complete"].get<bool>();
  MAPLESS_CHECK(j.contains("images") && j["images"].is_array(),
                name << ": images: missing or not a list");
  const auto& images = j["images"];
  MAPLESS_CHECK(images.size() <= static_cast<std::size_t>(io::kMaxKeyframes),
                name << ": " << images.size() << " images (at most " << io::kMaxKeyframes << ")");
  double last_distance = 0.0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const auto& e = images[i];
    const std::string where = "images[" + std::to_string(i) + "].";
    MAPLESS_CHECK(e.is_object(), name << ": " << where << ": not an object");
    MAPLESS_CHECK(number(e, "index", where) == static_cast<double>(i),
                  name << ": " << where << "index: must be " << i);
    StoredAppearanceImage image;
    image.distance_m = number(e, "distance_m", where);
    MAPLESS_CHECK(image.distance_m >= last_distance,
                  name << ": " << where << "distance_m goes backwards");
    last_distance = image.distance_m;
    image.odometry =
        Pose2{number(e, "x_m", where), number(e, "y_m", where), number(e, "theta_rad", where)};
    MAPLESS_CHECK(e.contains("file") && e["file"].is_string() &&
                      e["file"].get<std::string>() == ImageFile(static_cast<int>(i)),
                  name << ": " << where << "file: must be " << ImageFile(static_cast<int>(i)));
    if (files) files->push_back(e["file"].get<std::string>());
    if (e.contains("views")) {
      MAPLESS_CHECK(version == kAppearanceRouteViewsFormatVersion,
                    name << ": " << where << "views: only a version 2 route has views");
      image.views =
          ParseAppearanceViews(e["views"], static_cast<int>(i), route.visits, name + ": " + where);
    }
    route.images.push_back(image);
  }
  return route;
}

StoredAppearanceRoute LoadAppearanceRoute(const std::string& dir) {
  const std::string manifest = (fs::path(dir) / kManifest).string();
  MAPLESS_CHECK(fs::exists(manifest), dir << ": no appearance route here (no " << kManifest
                                          << "; teach one with `mapless teach --method "
                                             "eigenspace`)");
  std::vector<std::string> files;
  StoredAppearanceRoute route =
      ParseAppearanceManifest(io::ReadFile(manifest, io::kMaxManifestBytes), manifest, &files);
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string path = (fs::path(dir) / files[i]).string();
    cv::Mat low = io::ReadImage(path, cv::IMREAD_GRAYSCALE);
    MAPLESS_CHECK(low.cols == route.low_width && low.rows == route.low_height,
                  path << ": " << low.cols << "x" << low.rows << ", the route's images are "
                       << route.low_width << "x" << route.low_height);
    route.images[i].low = low;
    for (StoredAppearanceView& view : route.images[i].views) {
      const std::string view_path = (fs::path(dir) / view.file).string();
      view.low = io::ReadImage(view_path, cv::IMREAD_GRAYSCALE);
      MAPLESS_CHECK(view.low.cols == route.low_width && view.low.rows == route.low_height,
                    view_path << ": " << view.low.cols << "x" << view.low.rows
                              << ", the route's images are " << route.low_width << "x"
                              << route.low_height);
    }
  }
  return route;
}

}  // namespace mapless::route

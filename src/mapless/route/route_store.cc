#include "mapless/route/route_store.h"

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::route {
namespace {

std::string KeyframeStem(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "keyframes/%06d", index);
  return name;
}

std::string SerializeKeyframe(const Keyframe& kf) {
  cv::FileStorage fs(
      ".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  fs << "format"
     << "mapless-keyframe";
  fs << "version" << kRouteFormatVersion;
  fs << "index" << kf.index;
  fs << "t_ns" << std::to_string(kf.t_ns);
  fs << "keypoints" << kf.keypoints;
  fs << "descriptors" << kf.descriptors;
  fs << "segment_start_px" << kf.segment_start_px;
  fs << "segment_end_px" << kf.segment_end_px;
  fs << "end" << 1;  // last field: a truncated file lacks it
  return fs.releaseAndGetString();
}

Keyframe ReadKeyframe(const std::string& path, const std::string& thumbnail_path) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": keyframe file is missing");
  Keyframe kf;
  try {
    cv::FileStorage fs(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) throw InputError(path + ": cannot read keyframe file");
    if (static_cast<std::string>(fs["format"]) != "mapless-keyframe") {
      throw InputError(path + ": not a mapless keyframe file");
    }
    if (static_cast<int>(fs["end"]) != 1) throw InputError(path + ": truncated keyframe file");
    kf.index = static_cast<int>(fs["index"]);
    kf.t_ns = std::stoll(static_cast<std::string>(fs["t_ns"]));
    fs["keypoints"] >> kf.keypoints;
    fs["descriptors"] >> kf.descriptors;
    fs["segment_start_px"] >> kf.segment_start_px;
    fs["segment_end_px"] >> kf.segment_end_px;
  } catch (const cv::Exception& e) {
    throw InputError(path + ": corrupt keyframe file (" + e.err + ")");
  } catch (const std::invalid_argument&) {
    throw InputError(path + ": corrupt keyframe file (t_ns)");
  } catch (const std::out_of_range&) {
    throw InputError(path + ": corrupt keyframe file (t_ns)");
  }
  if (static_cast<std::size_t>(kf.descriptors.rows) != kf.keypoints.size()) {
    throw InputError(path + ": corrupt keyframe file (" + std::to_string(kf.keypoints.size()) +
                     " keypoints but " + std::to_string(kf.descriptors.rows) + " descriptors)");
  }
  if (kf.segment_start_px.size() != kf.segment_end_px.size()) {
    throw InputError(path + ": corrupt keyframe file (segment tracks of different lengths)");
  }
  try {
    kf.thumbnail = cv::imread(thumbnail_path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception&) {
    kf.thumbnail.release();
  }
  if (kf.thumbnail.empty())
    throw InputError(thumbnail_path + ": missing or corrupt keyframe image");
  return kf;
}

}  // namespace

RouteWriter::RouteWriter(std::string dir, std::string detector, int image_width, int image_height,
                         bool overwrite)
    : dir_(std::move(dir)),
      detector_(std::move(detector)),
      width_(image_width),
      height_(image_height) {
  MAPLESS_CHECK(image_width > 0 && image_height > 0, "RouteWriter: image size "
                                                         << image_width << "x" << image_height
                                                         << " must be positive");
  const std::filesystem::path manifest = std::filesystem::path(dir_) / "manifest.json";
  if (std::filesystem::exists(manifest) && !overwrite) {
    throw InputError(dir_ + ": already holds a route (manifest.json); choose another directory");
  }
  if (overwrite && std::filesystem::exists(std::filesystem::path(dir_) / "keyframes")) {
    std::filesystem::remove_all(std::filesystem::path(dir_) / "keyframes");
  }
  io::MakeDirectories((std::filesystem::path(dir_) / "keyframes").string());
  WriteManifest();
}

void RouteWriter::Append(const Keyframe& keyframe) {
  MAPLESS_CHECK(keyframe.index == keyframes(),
                "RouteWriter: keyframe index " << keyframe.index << ", expected " << keyframes());
  MAPLESS_CHECK(!keyframe.thumbnail.empty(),
                "RouteWriter: keyframe " << keyframe.index << " has no image");
  const std::filesystem::path base = std::filesystem::path(dir_) / KeyframeStem(keyframe.index);
  io::WriteFileAtomic(base.string() + ".yml", SerializeKeyframe(keyframe));
  io::WriteImageAtomic(base.string() + ".png", keyframe.thumbnail);
  entries_.push_back({keyframe.index, keyframe.t_ns});
  WriteManifest();
}

void RouteWriter::Finish() {
  complete_ = true;
  WriteManifest();
}

void RouteWriter::WriteManifest() const {
  nlohmann::json j;
  j["format"] = "mapless-route";
  j["version"] = kRouteFormatVersion;
  j["detector"] = detector_;
  j["image_width"] = width_;
  j["image_height"] = height_;
  j["complete"] = complete_;
  j["keyframes"] = nlohmann::json::array();
  for (const Entry& e : entries_) {
    j["keyframes"].push_back({{"index", e.index},
                              {"t_s", ToSeconds(e.t_ns)},
                              {"data", KeyframeStem(e.index) + ".yml"},
                              {"thumbnail", KeyframeStem(e.index) + ".png"}});
  }
  io::WriteFileAtomic((std::filesystem::path(dir_) / "manifest.json").string(), j.dump(1) + "\n");
}

Route LoadRoute(const std::string& dir) {
  const std::string manifest_path = (std::filesystem::path(dir) / "manifest.json").string();
  if (!std::filesystem::exists(manifest_path)) {
    throw InputError(manifest_path + ": no route here (manifest.json is missing)");
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(io::ReadFile(manifest_path));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(manifest_path + ": corrupt manifest (" + std::string(e.what()) + ")");
  }
  Route route;
  try {
    if (j.at("format").get<std::string>() != "mapless-route") {
      throw InputError(manifest_path + ": not a mapless route manifest");
    }
    const int version = j.at("version").get<int>();
    if (version != kRouteFormatVersion) {
      throw InputError(manifest_path + ": route format version " + std::to_string(version) +
                       " is not supported (this mapless reads version " +
                       std::to_string(kRouteFormatVersion) + ")");
    }
    route.detector = j.at("detector").get<std::string>();
    route.image_width = j.at("image_width").get<int>();
    route.image_height = j.at("image_height").get<int>();
    route.complete = j.at("complete").get<bool>();
    for (const auto& entry : j.at("keyframes")) {
      const std::string data =
          (std::filesystem::path(dir) / entry.at("data").get<std::string>()).string();
      const std::string thumb =
          (std::filesystem::path(dir) / entry.at("thumbnail").get<std::string>()).string();
      Keyframe kf = ReadKeyframe(data, thumb);
      if (kf.index != entry.at("index").get<int>() ||
          kf.index != static_cast<int>(route.keyframes.size())) {
        throw InputError(data + ": keyframe index " + std::to_string(kf.index) +
                         " does not match the manifest");
      }
      route.keyframes.push_back(std::move(kf));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(manifest_path + ": corrupt manifest (" + std::string(e.what()) + ")");
  }
  if (route.image_width <= 0 || route.image_height <= 0) {
    throw InputError(manifest_path + ": corrupt manifest (image size)");
  }
  return route;
}

}  // namespace mapless::route

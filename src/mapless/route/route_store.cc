#include "mapless/route/route_store.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string_view>

#include "mapless/core/check.h"
#include "mapless/features/features.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/io/limits.h"
#include "mapless/io/yaml_reader.h"
#include "mapless/route/manifest_text.h"

namespace mapless::route {
namespace {

std::string KeyframeStem(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "keyframes/%06d", index);
  return name;
}

// A path inside the route directory: relative, without "..".
bool InsideRoute(const std::string& relative) {
  if (relative.empty()) return false;
  const std::filesystem::path p(relative);
  if (p.is_absolute() || p.has_root_name() || p.has_root_directory()) return false;
  for (const auto& part : p) {
    if (part == "..") return false;
  }
  return true;
}

// An integer field of the manifest, checked before conversion (a float or an out-of-range number
// must not reach get<int>(), whose conversion would be undefined).
int ManifestInt(const nlohmann::json& j, const char* key, const std::string& name) {
  const nlohmann::json& v = j.at(key);
  if (!v.is_number_integer() || v.get<long long>() < -(1LL << 31) ||
      v.get<long long>() > (1LL << 31) - 1 ||
      (v.is_number_unsigned() && v.get<unsigned long long>() > (1ULL << 31))) {
    throw InputError(name + ": corrupt manifest (" + key + " is not an integer)");
  }
  return static_cast<int>(v.get<long long>());
}

// A keyframe entry's learned views (version 2): at most kMaxViewsPerKeyframe, files inside the
// route, finite offsets within the image's reach, visits no later than the route's.
std::vector<ManifestView> ParseViews(const nlohmann::json& entry, int index, int visits,
                                     const std::string& name) {
  std::vector<ManifestView> views;
  if (!entry.contains("views")) return views;
  const nlohmann::json& list = entry.at("views");
  const std::string where = name + ": keyframe " + std::to_string(index) + ": ";
  if (!list.is_array()) throw InputError(where + "corrupt manifest (views is not a list)");
  if (list.size() > static_cast<std::size_t>(kMaxViewsPerKeyframe)) {
    throw InputError(where + std::to_string(list.size()) + " views; the limit is " +
                     std::to_string(kMaxViewsPerKeyframe));
  }
  for (const auto& v : list) {
    ManifestView view;
    view.data = v.at("data").get<std::string>();
    const nlohmann::json& offset = v.at("offset_px");
    view.learned_at = ManifestInt(v, "learned_at", name);
    view.last_used = ManifestInt(v, "last_used", name);
    if (!offset.is_number() || !std::isfinite(offset.get<double>()) ||
        std::abs(offset.get<double>()) > io::kMaxImageSide) {
      throw InputError(where + "a view's offset_px is not a number of pixels within the image");
    }
    view.offset_px = offset.get<double>();
    if (!InsideRoute(view.data)) throw InputError(where + "a view names a file outside the route");
    if (view.learned_at < 1 || view.learned_at > visits || view.last_used < view.learned_at ||
        view.last_used > visits) {
      throw InputError(where + "a view learned at visit " + std::to_string(view.learned_at) +
                       " and last used at " + std::to_string(view.last_used) +
                       " does not fit the route's " + std::to_string(visits) + " visits");
    }
    views.push_back(std::move(view));
  }
  return views;
}

// What a repeat relies on in one keyframe, checked where the file is known: descriptors as the
// route's detector writes them, keypoints and tracks inside the image, the manifest's time.
void CheckKeyframe(const Keyframe& kf, const ManifestEntry& entry, const Manifest& manifest,
                   const features::DescriptorLayout& layout, const std::string& name) {
  if (kf.descriptors.rows > 0 &&
      (kf.descriptors.depth() != layout.type || kf.descriptors.cols != layout.length)) {
    throw InputError(name + ": descriptors of " + std::to_string(kf.descriptors.cols) + " " +
                     (kf.descriptors.depth() == CV_8U ? "bytes" : "floats") +
                     " do not match the route's detector '" + manifest.detector + "' (" +
                     std::to_string(layout.length) + " " +
                     (layout.type == CV_8U ? "bytes" : "floats") + ")");
  }
  const auto inside = [&](float x, float y) {
    return x >= -1.f && y >= -1.f && x <= static_cast<float>(manifest.image_width) + 1.f &&
           y <= static_cast<float>(manifest.image_height) + 1.f;
  };
  for (const cv::KeyPoint& k : kf.keypoints) {
    if (!inside(k.pt.x, k.pt.y)) {
      throw InputError(name + ": keypoint (" + std::to_string(k.pt.x) + ", " +
                       std::to_string(k.pt.y) + ") is outside the route's " +
                       std::to_string(manifest.image_width) + "x" +
                       std::to_string(manifest.image_height) + " image");
    }
  }
  for (const auto* track : {&kf.segment_start_px, &kf.segment_end_px}) {
    for (const cv::Point2f& p : *track) {
      if (!inside(p.x, p.y)) {
        throw InputError(name + ": a segment track point (" + std::to_string(p.x) + ", " +
                         std::to_string(p.y) + ") is outside the route's image");
      }
    }
  }
  if (std::abs(ToSeconds(kf.t_ns) - entry.t_s) > 1e-3) {
    throw InputError(name + ": t_ns says " + std::to_string(ToSeconds(kf.t_ns)) +
                     " s, the manifest says " + std::to_string(entry.t_s) + " s");
  }
}

// A keyframe's learned views from their files, each checked as a keyframe file of that keyframe.
std::vector<KeyframeView> LoadViews(const std::string& dir, const ManifestEntry& entry,
                                    const Manifest& manifest,
                                    const features::DescriptorLayout& layout) {
  std::vector<KeyframeView> views;
  for (const ManifestView& v : entry.views) {
    const std::string path = (std::filesystem::path(dir) / v.data).string();
    if (!std::filesystem::exists(path)) throw InputError(path + ": view file is missing");
    Keyframe kf = ParseKeyframe(io::ReadFile(path, io::kMaxKeyframeFileBytes), path);
    if (kf.index != entry.index) {
      throw InputError(path + ": a view of keyframe " + std::to_string(kf.index) +
                       ", listed under keyframe " + std::to_string(entry.index));
    }
    CheckKeyframe(kf, entry, manifest, layout, path);
    KeyframeView view;
    view.keypoints = std::move(kf.keypoints);
    view.descriptors = kf.descriptors;
    view.offset_px = v.offset_px;
    view.learned_at = v.learned_at;
    view.last_used = v.last_used;
    view.file = v.data;
    views.push_back(std::move(view));
  }
  return views;
}

}  // namespace

RouteWriter::RouteWriter(std::string dir, std::string detector, int image_width, int image_height)
    : dir_(std::move(dir)),
      detector_(std::move(detector)),
      width_(image_width),
      height_(image_height) {
  MAPLESS_CHECK(image_width > 0 && image_height > 0, "RouteWriter: image size "
                                                         << image_width << "x" << image_height
                                                         << " must be positive");
  const std::filesystem::path manifest = std::filesystem::path(dir_) / "manifest.json";
  if (std::filesystem::exists(manifest)) {
    throw InputError(dir_ + ": already holds a route (manifest.json); choose another directory");
  }
  io::MakeDirectories((std::filesystem::path(dir_) / "keyframes").string());
  WriteManifest();
}

RouteWriter::RouteWriter(std::string dir, const Manifest& manifest)
    : dir_(std::move(dir)),
      detector_(manifest.detector),
      width_(manifest.image_width),
      height_(manifest.image_height),
      complete_(manifest.complete) {
  for (const ManifestEntry& e : manifest.keyframes) entries_.push_back({e.index, e.t_s, {}});
}

std::unique_ptr<RouteWriter> RouteWriter::Reopen(const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / "manifest.json").string();
  const Manifest manifest = ParseManifest(io::ReadFile(path, io::kMaxManifestBytes), path);
  for (std::size_t i = 0; i < manifest.keyframes.size(); ++i) {
    const ManifestEntry& e = manifest.keyframes[i];
    if (!e.views.empty())
      throw InputError(path +
                       ": the route has learned views; a teach or a copy cannot go on "
                       "writing it");
    if (e.data != KeyframeStem(e.index) + ".yml" || e.thumbnail != KeyframeStem(e.index) + ".png")
      throw InputError(path + ": keyframe " + std::to_string(i) +
                       ": files are not where a mapless teach writes them");
  }
  return std::unique_ptr<RouteWriter>(new RouteWriter(dir, manifest));
}

std::string KeyframeFileStem(int index) { return KeyframeStem(index); }

void RouteWriter::Append(const Keyframe& keyframe) {
  MAPLESS_CHECK(!keyframe.thumbnail.empty(),
                "RouteWriter: keyframe " << keyframe.index << " has no image");
  const std::string base = (std::filesystem::path(dir_) / KeyframeStem(keyframe.index)).string();
  AppendEncoded(keyframe.index, keyframe.t_ns, SerializeKeyframe(keyframe),
                io::EncodeImage(keyframe.thumbnail, ".png", base + ".png"));
  Flush();
}

void RouteWriter::AppendEncoded(int index, Timestamp t_ns, std::string_view yml,
                                std::string_view png) {
  MAPLESS_CHECK(index == keyframes(),
                "RouteWriter: keyframe index " << index << ", expected " << keyframes());
  MAPLESS_CHECK(!complete_, "RouteWriter: keyframe " << index << " after the route's end");
  const std::filesystem::path base = std::filesystem::path(dir_) / KeyframeStem(index);
  io::WriteNewFile(base.string() + ".yml", yml);
  io::WriteNewFile(base.string() + ".png", png);
  pending_.push_back(base.string() + ".yml");
  pending_.push_back(base.string() + ".png");
  entries_.push_back({index, ToSeconds(t_ns), {}});
}

void RouteWriter::Flush() {
  io::SyncFiles(pending_);
  pending_.clear();
  WriteManifest();
}

void RouteWriter::Finish() {
  complete_ = true;
  Flush();
}

void RouteWriter::WriteManifest() const {
  nlohmann::json j;
  j["format"] = "mapless-route";
  j["version"] = kRouteFormatVersion;
  j["detector"] = detector_;
  j["image_width"] = width_;
  j["image_height"] = height_;
  j["complete"] = complete_;
  std::vector<std::string> entries;
  entries.reserve(entries_.size());
  for (const Entry& e : entries_) {
    if (e.text.empty()) {
      e.text = EntryText({{"index", e.index},
                          {"t_s", e.t_s},
                          {"data", KeyframeStem(e.index) + ".yml"},
                          {"thumbnail", KeyframeStem(e.index) + ".png"}});
    }
    entries.push_back(e.text);
  }
  io::WriteFileAtomic((std::filesystem::path(dir_) / "manifest.json").string(),
                      ManifestText(j, "keyframes", entries));
}

Manifest ParseManifest(const std::string& text, const std::string& name) {
  Manifest m;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    if (!j.is_object()) throw InputError(name + ": corrupt manifest (not a JSON object)");
    if (j.at("format").get<std::string>() != "mapless-route") {
      throw InputError(name + ": not a mapless route manifest");
    }
    m.version = ManifestInt(j, "version", name);
    if (m.version != kRouteFormatVersion && m.version != kRouteViewsFormatVersion) {
      throw InputError(name + ": route format version " + std::to_string(m.version) +
                       " is not supported (this mapless reads versions " +
                       std::to_string(kRouteFormatVersion) + " and " +
                       std::to_string(kRouteViewsFormatVersion) + ")");
    }
    if (m.version == kRouteViewsFormatVersion) m.visits = ManifestInt(j, "visits", name);
    if (m.visits < 0 || m.visits > kMaxRouteVisits)
      throw InputError(name + ": corrupt manifest (visits " + std::to_string(m.visits) +
                       "; must be 0 to " + std::to_string(kMaxRouteVisits) + ")");
    m.detector = j.at("detector").get<std::string>();
    m.image_width = ManifestInt(j, "image_width", name);
    m.image_height = ManifestInt(j, "image_height", name);
    m.complete = j.at("complete").get<bool>();
    const nlohmann::json& keyframes = j.at("keyframes");
    if (!keyframes.is_array())
      throw InputError(name + ": corrupt manifest (keyframes is not a list)");
    if (keyframes.size() > static_cast<std::size_t>(io::kMaxKeyframes)) {
      throw InputError(name + ": " + std::to_string(keyframes.size()) +
                       " keyframes; the limit is " + std::to_string(io::kMaxKeyframes));
    }
    for (const auto& entry : keyframes) {
      ManifestEntry e;
      e.index = ManifestInt(entry, "index", name);
      const nlohmann::json& t_s = entry.at("t_s");
      if (!t_s.is_number() || !std::isfinite(t_s.get<double>())) {
        throw InputError(name + ": keyframe " + std::to_string(e.index) +
                         ": t_s is not a number of seconds");
      }
      e.t_s = t_s.get<double>();
      e.data = entry.at("data").get<std::string>();
      e.thumbnail = entry.at("thumbnail").get<std::string>();
      if (e.index != static_cast<int>(m.keyframes.size())) {
        throw InputError(name + ": keyframe " + std::to_string(m.keyframes.size()) + " has index " +
                         std::to_string(e.index));
      }
      if (!InsideRoute(e.data) || !InsideRoute(e.thumbnail)) {
        throw InputError(name + ": keyframe " + std::to_string(e.index) +
                         " names a file outside the route directory");
      }
      if (m.version == kRouteViewsFormatVersion)
        e.views = ParseViews(entry, e.index, m.visits, name);
      m.keyframes.push_back(std::move(e));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(name + ": corrupt manifest (" + std::string(e.what()) + ")");
  }
  if (m.image_width < io::kMinImageSide || m.image_height < io::kMinImageSide ||
      m.image_width > io::kMaxImageSide || m.image_height > io::kMaxImageSide ||
      static_cast<std::int64_t>(m.image_width) * m.image_height > io::kMaxImagePixels) {
    throw InputError(name + ": image size " + std::to_string(m.image_width) + "x" +
                     std::to_string(m.image_height) + " is out of range (" +
                     std::to_string(io::kMinImageSide) + " to " +
                     std::to_string(io::kMaxImageSide) + " pixels a side, at most " +
                     std::to_string(io::kMaxImagePixels / 1'000'000) + " megapixels)");
  }
  return m;
}

Keyframe DecodeKeyframe(const std::string& yml, const std::string& png, const Manifest& header,
                        int index, Timestamp after_t_ns, const std::string& name) {
  features::DetectorType detector = features::DetectorType::kOrb;
  try {
    detector = features::ParseDetectorType(header.detector);
  } catch (const InputError& e) {
    throw InputError(name + ": detector: " + e.what());
  }
  Keyframe kf = ParseKeyframe(yml, name + ".yml");
  if (kf.index != index) {
    throw InputError(name + ".yml: keyframe index " + std::to_string(kf.index) + ", expected " +
                     std::to_string(index));
  }
  ManifestEntry entry;
  entry.index = index;
  entry.t_s = ToSeconds(kf.t_ns);
  CheckKeyframe(kf, entry, header, features::DescriptorLayoutOf(detector), name + ".yml");
  if (index > 0 && kf.t_ns <= after_t_ns) {
    throw InputError(name + ".yml: t_ns " + std::to_string(kf.t_ns) +
                     " is not after the previous keyframe's (" + std::to_string(after_t_ns) +
                     "): time goes backwards");
  }
  kf.thumbnail = io::DecodeImage(png, name + ".png", cv::IMREAD_GRAYSCALE);
  if (kf.thumbnail.cols > header.image_width || kf.thumbnail.rows > header.image_height) {
    throw InputError(name + ".png: keyframe image of " + std::to_string(kf.thumbnail.cols) + "x" +
                     std::to_string(kf.thumbnail.rows) + " is larger than the route's images");
  }
  return kf;
}

KeyframeView DecodeView(const std::string& yml, const Keyframe& keyframe, const Manifest& header,
                        const std::string& name) {
  features::DetectorType detector = features::DetectorType::kOrb;
  try {
    detector = features::ParseDetectorType(header.detector);
  } catch (const InputError& e) {
    throw InputError(name + ": detector: " + e.what());
  }
  Keyframe kf = ParseKeyframe(yml, name);
  if (kf.index != keyframe.index) {
    throw InputError(name + ": a view of keyframe " + std::to_string(kf.index) +
                     ", offered as a view of keyframe " + std::to_string(keyframe.index));
  }
  ManifestEntry entry;
  entry.index = keyframe.index;
  entry.t_s = ToSeconds(keyframe.t_ns);
  CheckKeyframe(kf, entry, header, features::DescriptorLayoutOf(detector), name);
  KeyframeView view;
  view.keypoints = std::move(kf.keypoints);
  view.descriptors = kf.descriptors;
  return view;
}

Route LoadRoute(const std::string& dir) {
  const std::string manifest_path = (std::filesystem::path(dir) / "manifest.json").string();
  if (!std::filesystem::exists(manifest_path)) {
    throw InputError(manifest_path + ": no route here (manifest.json is missing)");
  }
  const Manifest manifest =
      ParseManifest(io::ReadFile(manifest_path, io::kMaxManifestBytes), manifest_path);
  features::DetectorType detector = features::DetectorType::kOrb;
  try {
    detector = features::ParseDetectorType(manifest.detector);
  } catch (const InputError& e) {
    throw InputError(manifest_path + ": detector: " + e.what());
  }
  const features::DescriptorLayout layout = features::DescriptorLayoutOf(detector);
  if (manifest.keyframes.size() < 2) {
    throw InputError(manifest_path + ": the route has " +
                     std::to_string(manifest.keyframes.size()) + " keyframe" +
                     (manifest.keyframes.size() == 1 ? "" : "s") +
                     "; a route needs at least 2 to be repeated");
  }
  Route route;
  route.detector = manifest.detector;
  route.image_width = manifest.image_width;
  route.image_height = manifest.image_height;
  route.complete = manifest.complete;
  route.visits = manifest.visits;
  for (const ManifestEntry& entry : manifest.keyframes) {
    const std::string data = (std::filesystem::path(dir) / entry.data).string();
    const std::string thumb = (std::filesystem::path(dir) / entry.thumbnail).string();
    if (!std::filesystem::exists(data)) throw InputError(data + ": keyframe file is missing");
    Keyframe kf = ParseKeyframe(io::ReadFile(data, io::kMaxKeyframeFileBytes), data);
    if (kf.index != entry.index) {
      throw InputError(data + ": keyframe index " + std::to_string(kf.index) +
                       " does not match the manifest");
    }
    CheckKeyframe(kf, entry, manifest, layout, data);
    if (!route.keyframes.empty() && kf.t_ns <= route.keyframes.back().t_ns) {
      throw InputError(data + ": t_ns " + std::to_string(kf.t_ns) +
                       " is not after the previous keyframe's (" +
                       std::to_string(route.keyframes.back().t_ns) + "): time goes backwards");
    }
    if (!std::filesystem::exists(thumb)) throw InputError(thumb + ": keyframe image is missing");
    kf.thumbnail = io::ReadImage(thumb, cv::IMREAD_GRAYSCALE);
    if (kf.thumbnail.cols > route.image_width || kf.thumbnail.rows > route.image_height) {
      throw InputError(thumb + ": keyframe image of " + std::to_string(kf.thumbnail.cols) + "x" +
                       std::to_string(kf.thumbnail.rows) + " is larger than the route's images");
    }
    kf.views = LoadViews(dir, entry, manifest, layout);
    route.keyframes.push_back(std::move(kf));
  }
  return route;
}

}  // namespace mapless::route

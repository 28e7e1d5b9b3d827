#include "mapless/route/route_store.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <nlohmann/json.hpp>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string_view>

#include "mapless/core/check.h"
#include "mapless/features/features.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/io/limits.h"
#include "mapless/io/yaml_reader.h"

namespace mapless::route {
namespace {

std::string KeyframeStem(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "keyframes/%06d", index);
  return name;
}

std::string SerializeKeyframeYaml(const Keyframe& kf) {
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

// Conversions that would be undefined for out-of-range values are checked first.
bool FitsFloat(double v) {
  return std::isfinite(v) && std::abs(v) <= static_cast<double>(std::numeric_limits<float>::max());
}
bool IsInt(double v) {
  return std::isfinite(v) && v == std::floor(v) &&
         v >= static_cast<double>(std::numeric_limits<int>::min()) &&
         v <= static_cast<double>(std::numeric_limits<int>::max());
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

// A fast reader for keyframe files exactly as SerializeKeyframeYaml writes them (OpenCV's YAML
// layout, fields in their order). yaml-cpp takes about 25 ms for a keyframe of 500 features; this
// takes well under 1 ms, which a follower catching up on a long route needs (fleet/). Anything it
// does not recognise, it leaves to yaml-cpp (std::nullopt), which reads every valid file and names
// what is wrong in an invalid one; what it accepts passes the same checks. Fuzzed with
// ParseKeyframe (fuzz/ harness RouteKeyframe).
class CanonicalReader {
 public:
  explicit CanonicalReader(const std::string& text) : s_(text) {}
  bool Literal(std::string_view lit) {
    if (s_.compare(pos_, lit.size(), lit) != 0) return false;
    pos_ += lit.size();
    return true;
  }
  void SkipSpace() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\n')) ++pos_;
  }
  // A number as OpenCV writes it: [-+0-9.eE] only (no inf, nan or hex).
  bool Number(double* v) {
    const std::size_t start = pos_;
    while (pos_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[pos_])) ||
                                s_[pos_] == '-' || s_[pos_] == '+' || s_[pos_] == '.' ||
                                s_[pos_] == 'e' || s_[pos_] == 'E'))
      ++pos_;
    if (pos_ == start || pos_ - start > 40) return false;
    const std::string token = s_.substr(start, pos_ - start);
    char* end = nullptr;
    *v = std::strtod(token.c_str(), &end);
    return end == token.c_str() + token.size() && std::isfinite(*v);
  }
  bool Integer(long long lo, long long hi, long long* v) {
    double d = 0.0;
    if (!Number(&d) || d != std::floor(d) || d < static_cast<double>(lo) ||
        d > static_cast<double>(hi))
      return false;
    *v = static_cast<long long>(d);
    return true;
  }
  // "[ a, b, ... ]" or "[]", at most `max` numbers.
  bool FlowList(std::size_t max, std::vector<double>* out) {
    out->clear();
    if (!Literal("[")) return false;
    SkipSpace();
    if (Literal("]")) return true;
    while (true) {
      double v = 0.0;
      if (out->size() >= max || !Number(&v)) return false;
      out->push_back(v);
      SkipSpace();
      if (Literal("]")) return true;
      if (!Literal(",")) return false;
      SkipSpace();
    }
  }
  bool AtEnd() {
    SkipSpace();
    return pos_ == s_.size();
  }
  bool Peek(char c) const { return pos_ < s_.size() && s_[pos_] == c; }

 private:
  const std::string& s_;
  std::size_t pos_ = 0;
};

std::optional<Keyframe> ParseCanonicalKeyframe(const std::string& text) {
  CanonicalReader in(text);
  Keyframe kf;
  long long v = 0;
  in.Literal("%YAML:1.0\n");
  if (!in.Literal("---\nformat: mapless-keyframe\nversion: ") ||
      !in.Integer(kRouteFormatVersion, kRouteFormatVersion, &v) || !in.Literal("\nindex: ") ||
      !in.Integer(0, std::numeric_limits<int>::max(), &v))
    return std::nullopt;
  kf.index = static_cast<int>(v);
  if (!in.Literal("\nt_ns: \"")) return std::nullopt;
  double t = 0.0;
  if (!in.Number(&t) || !in.Literal("\"\nkeypoints:\n")) return std::nullopt;
  // t_ns is written as a decimal string of a 64-bit integer: a double cannot hold every one, so
  // anything above 2^53 ns (104 days) goes to the general reader.
  if (t != std::floor(t) || std::abs(t) > 9007199254740992.0) return std::nullopt;
  kf.t_ns = static_cast<Timestamp>(t);
  in.SkipSpace();
  std::vector<double> values;
  if (in.Peek('[')) {
    if (!in.FlowList(0, &values)) return std::nullopt;
  } else {
    while (in.Literal("- ")) {
      if (!in.FlowList(7, &values) || values.size() != 7) return std::nullopt;
      for (int i = 0; i < 5; ++i)
        if (!FitsFloat(values[static_cast<std::size_t>(i)])) return std::nullopt;
      if (!IsInt(values[5]) || !IsInt(values[6])) return std::nullopt;
      if (kf.keypoints.size() >= static_cast<std::size_t>(io::kMaxKeypoints)) return std::nullopt;
      kf.keypoints.emplace_back(static_cast<float>(values[0]), static_cast<float>(values[1]),
                                static_cast<float>(values[2]), static_cast<float>(values[3]),
                                static_cast<float>(values[4]), static_cast<int>(values[5]),
                                static_cast<int>(values[6]));
      in.SkipSpace();
    }
  }
  in.SkipSpace();
  long long rows = 0, cols = 0;
  if (!in.Literal("descriptors: !!opencv-matrix\n")) return std::nullopt;
  in.SkipSpace();
  if (!in.Literal("rows: ") || !in.Integer(0, io::kMaxKeypoints, &rows)) return std::nullopt;
  in.SkipSpace();
  if (!in.Literal("cols: ") || !in.Integer(0, 4096, &cols)) return std::nullopt;
  in.SkipSpace();
  const bool bytes = in.Literal("dt: u");
  if (!bytes && !in.Literal("dt: f")) return std::nullopt;
  in.SkipSpace();
  if (!in.Literal("data: ") ||
      !in.FlowList(static_cast<std::size_t>(rows * cols), &values) ||
      values.size() != static_cast<std::size_t>(rows * cols))
    return std::nullopt;
  if (rows * cols > 0) {
    kf.descriptors.create(static_cast<int>(rows), static_cast<int>(cols),
                          bytes ? CV_8UC1 : CV_32FC1);
    for (std::size_t i = 0; i < values.size(); ++i) {
      const int r = static_cast<int>(i / static_cast<std::size_t>(cols));
      const int c = static_cast<int>(i % static_cast<std::size_t>(cols));
      if (bytes) {
        if (values[i] < 0.0 || values[i] > 255.0 || values[i] != std::floor(values[i]))
          return std::nullopt;
        kf.descriptors.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(values[i]);
      } else {
        if (!FitsFloat(values[i])) return std::nullopt;
        kf.descriptors.at<float>(r, c) = static_cast<float>(values[i]);
      }
    }
  }
  for (auto [key, track] : {std::pair<const char*, std::vector<cv::Point2f>*>{
                                "segment_start_px: ", &kf.segment_start_px},
                            {"segment_end_px: ", &kf.segment_end_px}}) {
    in.SkipSpace();
    if (!in.Literal(key) || !in.FlowList(2 * static_cast<std::size_t>(io::kMaxKeypoints), &values) ||
        values.size() % 2 != 0)
      return std::nullopt;
    for (std::size_t i = 0; i < values.size(); i += 2) {
      if (!FitsFloat(values[i]) || !FitsFloat(values[i + 1])) return std::nullopt;
      track->emplace_back(static_cast<float>(values[i]), static_cast<float>(values[i + 1]));
    }
  }
  in.SkipSpace();
  if (!in.Literal("end: 1") || !in.AtEnd()) return std::nullopt;
  return kf;
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
  for (const ManifestEntry& e : manifest.keyframes) entries_.push_back({e.index, e.t_s});
}

std::unique_ptr<RouteWriter> RouteWriter::Reopen(const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / "manifest.json").string();
  const Manifest manifest = ParseManifest(io::ReadFile(path, io::kMaxManifestBytes), path);
  for (std::size_t i = 0; i < manifest.keyframes.size(); ++i) {
    const ManifestEntry& e = manifest.keyframes[i];
    if (e.data != KeyframeStem(e.index) + ".yml" || e.thumbnail != KeyframeStem(e.index) + ".png")
      throw InputError(path + ": keyframe " + std::to_string(i) +
                       ": files are not where a mapless teach writes them");
  }
  return std::unique_ptr<RouteWriter>(new RouteWriter(dir, manifest));
}

std::string KeyframeFileStem(int index) { return KeyframeStem(index); }

std::string SerializeKeyframe(const Keyframe& keyframe) { return SerializeKeyframeYaml(keyframe); }

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
  entries_.push_back({index, ToSeconds(t_ns)});
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
  j["keyframes"] = nlohmann::json::array();
  for (const Entry& e : entries_) {
    j["keyframes"].push_back({{"index", e.index},
                              {"t_s", e.t_s},
                              {"data", KeyframeStem(e.index) + ".yml"},
                              {"thumbnail", KeyframeStem(e.index) + ".png"}});
  }
  io::WriteFileAtomic((std::filesystem::path(dir_) / "manifest.json").string(), j.dump(1) + "\n");
}

Keyframe ParseKeyframe(const std::string& text, const std::string& name) {
  if (std::optional<Keyframe> kf = ParseCanonicalKeyframe(text)) {
    if (static_cast<std::size_t>(kf->descriptors.rows) == kf->keypoints.size() &&
        kf->segment_start_px.size() == kf->segment_end_px.size())
      return std::move(*kf);
    // Inconsistent counts: the general reader names the problem.
  }
  // Written by OpenCV's FileStorage, read with yaml-cpp: OpenCV 4.6's own YAML reader hangs on
  // some corrupt files (found by fuzz/fuzz_route_keyframe), yaml-cpp refuses them. OpenCV starts
  // the file with the non-standard directive "%YAML:1.0", which is dropped first.
  std::string yaml = text;
  constexpr std::string_view kOpenCvHeader = "%YAML:1.0\n";
  if (yaml.compare(0, kOpenCvHeader.size(), kOpenCvHeader) == 0)
    yaml.erase(0, kOpenCvHeader.size());
  return io::WithYamlErrors(name, [&] {
    const io::YamlMap root = io::YamlMap::LoadString(yaml, name);
    if (root.GetString("format", "") != "mapless-keyframe") {
      throw InputError(name + ": not a mapless keyframe file");
    }
    if (!root.Has("end") || root.GetInt("end") != 1) {
      throw InputError(name + ": truncated keyframe file");
    }
    Keyframe kf;
    kf.index = root.GetInt("index");
    if (kf.index < 0) root.Fail("index", "must be >= 0");
    try {
      kf.t_ns = std::stoll(root.GetString("t_ns"));
    } catch (const std::logic_error&) {  // invalid_argument, out_of_range
      root.Fail("t_ns", "expected a whole number of nanoseconds");
    }
    if (root.Has("keypoints")) {
      const std::vector<io::YamlMap> keypoints = root.GetList("keypoints");
      if (keypoints.size() > static_cast<std::size_t>(io::kMaxKeypoints)) {
        root.Fail("keypoints", std::to_string(keypoints.size()) + " keypoints; the limit is " +
                                   std::to_string(io::kMaxKeypoints));
      }
      for (const io::YamlMap& k : keypoints) {
        const std::vector<double> v = k.AsDoubles(7);  // x, y, size, angle, response, octave, id
        for (int i = 0; i < 5; ++i) {
          if (!FitsFloat(v[static_cast<std::size_t>(i)])) k.Fail("", "a value is out of range");
        }
        if (!IsInt(v[5]) || !IsInt(v[6])) k.Fail("", "octave and class id must be integers");
        kf.keypoints.emplace_back(static_cast<float>(v[0]), static_cast<float>(v[1]),
                                  static_cast<float>(v[2]), static_cast<float>(v[3]),
                                  static_cast<float>(v[4]), static_cast<int>(v[5]),
                                  static_cast<int>(v[6]));
      }
    }
    if (root.Has("descriptors")) {
      const io::YamlMap d = root.GetMap("descriptors");
      const int rows = d.GetInt("rows");
      const int cols = d.GetInt("cols");
      const std::string dt = d.GetString("dt");
      if (dt != "u" && dt != "f") d.Fail("dt", "expected u (ORB) or f (float descriptors)");
      if (rows < 0 || cols < 0 || rows > io::kMaxKeypoints || cols > 4096) {  // rows * cols fits
        d.Fail("", "implausible size " + std::to_string(rows) + "x" + std::to_string(cols));
      }
      const std::vector<double> data = d.GetDoubles("data", rows * cols);
      if (rows * cols > 0) {
        kf.descriptors.create(rows, cols, dt == "u" ? CV_8UC1 : CV_32FC1);
        for (int i = 0; i < rows * cols; ++i) {
          const double value = data[static_cast<std::size_t>(i)];
          if (dt == "u") {
            if (value < 0.0 || value > 255.0) d.Fail("data", "a value is not a byte");
            kf.descriptors.at<std::uint8_t>(i / cols, i % cols) = static_cast<std::uint8_t>(value);
          } else {
            if (!FitsFloat(value)) d.Fail("data", "a value is out of range");
            kf.descriptors.at<float>(i / cols, i % cols) = static_cast<float>(value);
          }
        }
      }
    }
    const auto points = [&](const char* key) {
      std::vector<cv::Point2f> out;
      if (!root.Has(key)) return out;
      const std::vector<double> v = root.GetDoubles(key, -1);
      if (v.size() % 2 != 0) root.Fail(key, "expected x, y pairs");
      for (std::size_t i = 0; i + 1 < v.size(); i += 2) {
        if (!FitsFloat(v[i]) || !FitsFloat(v[i + 1])) root.Fail(key, "a value is out of range");
        out.emplace_back(static_cast<float>(v[i]), static_cast<float>(v[i + 1]));
      }
      return out;
    };
    kf.segment_start_px = points("segment_start_px");
    kf.segment_end_px = points("segment_end_px");
    if (static_cast<std::size_t>(kf.descriptors.rows) != kf.keypoints.size()) {
      throw InputError(name + ": corrupt keyframe file (" + std::to_string(kf.keypoints.size()) +
                       " keypoints but " + std::to_string(kf.descriptors.rows) + " descriptors)");
    }
    if (kf.segment_start_px.size() != kf.segment_end_px.size()) {
      throw InputError(name + ": corrupt keyframe file (segment tracks of different lengths)");
    }
    return kf;
  });
}

Manifest ParseManifest(const std::string& text, const std::string& name) {
  Manifest m;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    if (!j.is_object()) throw InputError(name + ": corrupt manifest (not a JSON object)");
    if (j.at("format").get<std::string>() != "mapless-route") {
      throw InputError(name + ": not a mapless route manifest");
    }
    const int version = ManifestInt(j, "version", name);
    if (version != kRouteFormatVersion) {
      throw InputError(name + ": route format version " + std::to_string(version) +
                       " is not supported (this mapless reads version " +
                       std::to_string(kRouteFormatVersion) + ")");
    }
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
                     std::to_string(io::kMaxImageSide) + " a side)");
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
    route.keyframes.push_back(std::move(kf));
  }
  return route;
}

}  // namespace mapless::route

// Keyframe data files (route/keyframes/NNNNNN.yml): written by OpenCV's FileStorage, read by a
// fast reader for exactly that layout or, for anything else, by yaml-cpp (route_store.h).
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <opencv2/core/persistence.hpp>
#include <optional>
#include <string_view>

#include "mapless/core/check.h"
#include "mapless/io/limits.h"
#include "mapless/io/yaml_reader.h"
#include "mapless/route/route_store.h"

namespace mapless::route {
namespace {

// Conversions that would be undefined for out-of-range values are checked first.
bool FitsFloat(double v) {
  return std::isfinite(v) && std::abs(v) <= static_cast<double>(std::numeric_limits<float>::max());
}
bool IsInt(double v) {
  return std::isfinite(v) && v == std::floor(v) &&
         v >= static_cast<double>(std::numeric_limits<int>::min()) &&
         v <= static_cast<double>(std::numeric_limits<int>::max());
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
    while (pos_ < s_.size() &&
           (std::isdigit(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '-' ||
            s_[pos_] == '+' || s_[pos_] == '.' || s_[pos_] == 'e' || s_[pos_] == 'E'))
      ++pos_;
    if (pos_ == start || pos_ - start > 40) return false;
    // Whole numbers (descriptor bytes, most of a keyframe file, and floats such as "151.") without
    // strtod: exact up to 15 digits, as strtod would give them.
    std::size_t i = start + (s_[start] == '-' ? 1 : 0);
    if (i < pos_ && pos_ - i <= 15) {
      double whole = 0.0;
      while (i < pos_ && std::isdigit(static_cast<unsigned char>(s_[i])))
        whole = whole * 10.0 + (s_[i++] - '0');
      if (i + 1 == pos_ && i > start && s_[i] == '.' &&
          std::isdigit(static_cast<unsigned char>(s_[i - 1])))
        ++i;  // "151.": OpenCV writes a whole float so
      if (i == pos_) {
        *v = s_[start] == '-' ? -whole : whole;
        return true;
      }
    }
    // std::from_chars: correctly rounded like strtod, without the locale or a copy of the token.
    // It refuses a leading '+' and results that underflow, which strtod takes: those go to strtod.
    const char* first = s_.data() + start;
    const char* last = s_.data() + pos_;
    if (s_[start] != '+') {
      const std::from_chars_result r = std::from_chars(first, last, *v);
      if (r.ec == std::errc() && r.ptr == last) return std::isfinite(*v);
    }
    const std::string token(first, last);
    char* end = nullptr;
    *v = std::strtod(token.c_str(), &end);
    return end == token.c_str() + token.size() && std::isfinite(*v);
  }
  // True when a whole number (an optional '-' and digits only) starts here; reads nothing.
  bool Digits() const {
    std::size_t i = pos_ + (pos_ < s_.size() && s_[pos_] == '-' ? 1 : 0);
    const std::size_t first = i;
    while (i < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i]))) ++i;
    return i > first && i < s_.size() && s_[i] == '"';
  }
  bool Integer(long long lo, long long hi, long long* v) {
    double d = 0.0;
    const std::size_t start = pos_;
    if (!Number(&d) || d != std::floor(d) || d < static_cast<double>(lo) ||
        d > static_cast<double>(hi))
      return false;
    // Written as a whole number ("1", not "1.0" or "1e0"): else the general reader decides.
    for (std::size_t i = start; i < pos_; ++i)
      if (!std::isdigit(static_cast<unsigned char>(s_[i])) && !(i == start && s_[i] == '-'))
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
  if (!in.Digits() || !in.Number(&t) || !in.Literal("\"\nkeypoints:\n")) return std::nullopt;
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
  if (!in.Literal("data: ") || !in.FlowList(static_cast<std::size_t>(rows * cols), &values) ||
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
  for (auto [key, track] : {std::pair<const char*, std::vector<cv::Point2f>*>{"segment_start_px: ",
                                                                              &kf.segment_start_px},
                            {"segment_end_px: ", &kf.segment_end_px}}) {
    in.SkipSpace();
    if (!in.Literal(key) ||
        !in.FlowList(2 * static_cast<std::size_t>(io::kMaxKeypoints), &values) ||
        values.size() % 2 != 0)
      return std::nullopt;
    for (std::size_t i = 0; i < values.size(); i += 2) {
      if (!FitsFloat(values[i]) || !FitsFloat(values[i + 1])) return std::nullopt;
      track->emplace_back(static_cast<float>(values[i]), static_cast<float>(values[i + 1]));
    }
  }
  in.SkipSpace();
  if (in.Literal("odometry: ")) {
    if (!in.FlowList(3, &values) || values.size() != 3) return std::nullopt;
    kf.odometry = Pose2{values[0], values[1], values[2]};
    in.SkipSpace();
  }
  if (!in.Literal("end: 1") || !in.AtEnd()) return std::nullopt;
  return kf;
}
}  // namespace

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
  if (kf.odometry) {
    // To the micrometre and the nanoradian: odometry recorded as a quaternion (nav_msgs/Odometry)
    // gives back the yaw within a few units of the last bit, and a route taught from the
    // recording must be the route taught live, file for file.
    const auto round = [](double v, double unit) { return std::round(v / unit) * unit; };
    fs << "odometry"
       << std::vector<double>{round(kf.odometry->x_m, 1e-6), round(kf.odometry->y_m, 1e-6),
                              round(kf.odometry->theta_rad, 1e-9)};
  }
  fs << "end" << 1;  // last field: a truncated file lacks it
  return fs.releaseAndGetString();
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
    // The whole value: "1 trailing" is a string, not version 1 (it was accepted).
    if (root.GetString("version", "") != std::to_string(kRouteFormatVersion))
      root.Fail("version", "expected " + std::to_string(kRouteFormatVersion) + ", got '" +
                               root.GetString("version", "") + "'");
    Keyframe kf;
    kf.index = root.GetInt("index");
    if (kf.index < 0) root.Fail("index", "must be >= 0");
    // The whole string, digits only (std::stoll took "0.5" as 0 and "12abc" as 12).
    const std::string t_text = root.GetString("t_ns");
    const std::from_chars_result t_read =
        std::from_chars(t_text.data(), t_text.data() + t_text.size(), kf.t_ns);
    if (t_text.empty() || t_read.ec != std::errc() || t_read.ptr != t_text.data() + t_text.size())
      root.Fail("t_ns", "expected a whole number of nanoseconds, got '" + t_text + "'");
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
    if (root.Has("odometry")) {
      const std::vector<double> v = root.GetDoubles("odometry", 3);  // x, y, yaw
      for (const double x : v)
        if (!std::isfinite(x)) root.Fail("odometry", "a value is not finite");
      kf.odometry = Pose2{v[0], v[1], v[2]};
    }
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

}  // namespace mapless::route

#include "mapless/recording/camera_info_yaml.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"
#include "mapless/io/yaml_reader.h"

namespace mapless::recording {

namespace {

// A {rows, cols, data} matrix of `rows` x `cols` (cols < 0: any number of columns, one row).
std::vector<double> Matrix(const io::YamlMap& parent, const std::string& key, int rows, int cols) {
  const io::YamlMap m = parent.GetMap(key);
  m.CheckKnownKeys({"rows", "cols", "data"});
  const int r = m.GetInt("rows");
  const int c = m.GetInt("cols");
  if (r != rows || (cols >= 0 && c != cols) || c < 0 || c > 64) {
    m.Fail("rows", "expected " + std::to_string(rows) + " x " +
                       (cols >= 0 ? std::to_string(cols) : std::string("N (N <= 64)")) + ", got " +
                       std::to_string(r) + " x " + std::to_string(c));
  }
  const std::vector<double> data = m.GetDoubles("data", r * c);
  for (double v : data)
    if (!std::isfinite(v)) m.Fail("data", "a number is not finite");
  return data;
}

}  // namespace

rosmsg::CameraInfoFields ParseCameraInfoYaml(const std::string& text, const std::string& name) {
  return io::WithYamlErrors(name, [&] {
    const io::YamlMap y = io::YamlMap::LoadString(text, name);
    y.CheckKnownKeys({"image_width", "image_height", "camera_name", "camera_matrix",
                      "distortion_model", "distortion_coefficients", "rectification_matrix",
                      "projection_matrix"});
    rosmsg::CameraInfoFields info;
    const int width = y.GetInt("image_width");
    const int height = y.GetInt("image_height");
    if (width < io::kMinImageSide || width > io::kMaxImageSide)
      y.Fail("image_width", "expected " + std::to_string(io::kMinImageSide) + " to " +
                                std::to_string(io::kMaxImageSide) + " pixels");
    if (height < io::kMinImageSide || height > io::kMaxImageSide)
      y.Fail("image_height", "expected " + std::to_string(io::kMinImageSide) + " to " +
                                 std::to_string(io::kMaxImageSide) + " pixels");
    if (std::int64_t{width} * height > io::kMaxImagePixels)
      y.Fail("image_height", std::to_string(width) + "x" + std::to_string(height) + ": at most " +
                                 std::to_string(io::kMaxImagePixels / 1'000'000) + " megapixels");
    info.width = static_cast<std::uint32_t>(width);
    info.height = static_cast<std::uint32_t>(height);
    const std::vector<double> k = Matrix(y, "camera_matrix", 3, 3);
    if (!(k[0] > 0.0 && k[4] > 0.0))
      y.Fail("camera_matrix", "the focal lengths fx, fy (data[0], data[4]) must be positive");
    std::copy(k.begin(), k.end(), info.k.begin());
    info.distortion_model = y.GetString("distortion_model", "plumb_bob");
    // ROS names them plumb_bob, rational_polynomial, equidistant: a plain word.
    if (info.distortion_model.empty() || info.distortion_model.size() > 64 ||
        !std::all_of(info.distortion_model.begin(), info.distortion_model.end(), [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
        })) {
      y.Fail("distortion_model", "expected a model name such as plumb_bob (letters, digits, _)");
    }
    if (y.Has("distortion_coefficients")) info.d = Matrix(y, "distortion_coefficients", 1, -1);
    info.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (y.Has("rectification_matrix")) {
      const std::vector<double> r = Matrix(y, "rectification_matrix", 3, 3);
      std::copy(r.begin(), r.end(), info.r.begin());
    }
    info.p = {k[0], k[1], k[2], 0, k[3], k[4], k[5], 0, k[6], k[7], k[8], 0};
    if (y.Has("projection_matrix")) {
      const std::vector<double> p = Matrix(y, "projection_matrix", 3, 4);
      std::copy(p.begin(), p.end(), info.p.begin());
    }
    return info;
  });
}

rosmsg::CameraInfoFields LoadCameraInfoYaml(const std::string& path) {
  return ParseCameraInfoYaml(io::ReadFile(path, io::kMaxYamlFileBytes), path);
}

std::string FormatCameraInfoYaml(const rosmsg::CameraInfoFields& info) {
  std::ostringstream out;
  out.precision(17);
  const auto matrix = [&](const char* key, int rows, int cols, const double* data) {
    out << key << ":\n  rows: " << rows << "\n  cols: " << cols << "\n  data: [";
    for (int i = 0; i < rows * cols; ++i) out << (i ? ", " : "") << data[i];
    out << "]\n";
  };
  out << "image_width: " << info.width << "\nimage_height: " << info.height
      << "\ncamera_name: camera\n";
  matrix("camera_matrix", 3, 3, info.k.data());
  out << "distortion_model: " << info.distortion_model << "\n";
  matrix("distortion_coefficients", 1, static_cast<int>(info.d.size()), info.d.data());
  matrix("rectification_matrix", 3, 3, info.r.data());
  matrix("projection_matrix", 3, 4, info.p.data());
  return out.str();
}

}  // namespace mapless::recording

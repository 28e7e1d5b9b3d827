#include "cli_common.h"

#include <cmath>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::app {

std::vector<double> ParseNumbers(const std::string& text, const std::string& option, int n,
                                 const std::string& form) {
  const std::string error =
      option + " '" + text + "': expected " + form + " (" + std::to_string(n) + " numbers)";
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(v.back())) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError(error);
    }
  }
  if (static_cast<int>(v.size()) != n) throw InputError(error);
  return v;
}

bool ParseEndByLocalScale(const std::string& end) {
  if (end != "scale" && end != "switching")
    throw InputError("--end '" + end + "': expected scale or switching");
  return end == "scale";
}

Pose2 ParsePoseDeg(const std::string& text, const std::string& option) {
  const std::vector<double> v = ParseNumbers(text, option, 3, "X,Y,THETA_DEG");
  return Pose2{v[0], v[1], WrapAngle(DegToRad(v[2]))};
}

JsonLines::JsonLines(const std::string& path) {
  if (path.empty() || path == "-") return;
  file_ = std::make_unique<io::JournalFile>(path);
}

void JsonLines::Write(const nlohmann::json& j) {
  if (file_) {
    file_->Append(j.dump());
    return;
  }
  std::cout << j.dump() << "\n";
  std::cout.flush();
}

sim::DriveOptions LoadDriveOptions(const std::string& config_path) {
  if (config_path.empty()) return sim::DriveOptions{};
  return sim::ParseDriveOptions(io::ReadFile(config_path), config_path);
}

cv::Mat ReadImageOrThrow(const std::string& path, int flags) {
  cv::Mat img;
  try {
    img = cv::imread(path, flags);
  } catch (const cv::Exception&) {
    img.release();
  }
  if (img.empty()) throw InputError(path + ": cannot read image (missing, or not an image file)");
  return img;
}

void RequireSameSize(const cv::Mat& image, const std::string& path, const cv::Mat& reference,
                     const std::string& reference_path) {
  if (image.size() == reference.size()) return;
  throw InputError(path + ": size " + std::to_string(image.cols) + "x" +
                   std::to_string(image.rows) + " differs from " + reference_path + " (" +
                   std::to_string(reference.cols) + "x" + std::to_string(reference.rows) + ")");
}

}  // namespace mapless::app

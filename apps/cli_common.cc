#include "cli_common.h"

#include <cmath>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/yaml_reader.h"

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

Pose2 ParsePoseDeg(const std::string& text, const std::string& option) {
  const std::vector<double> v = ParseNumbers(text, option, 3, "X,Y,THETA_DEG");
  return Pose2{v[0], v[1], WrapAngle(DegToRad(v[2]))};
}

JsonLines::JsonLines(const std::string& path) {
  if (path.empty() || path == "-") return;
  file_.open(path, std::ios::out | std::ios::trunc);
  if (!file_) throw InputError(path + ": cannot write");
}

void JsonLines::Write(const nlohmann::json& j) {
  std::ostream& out = file_.is_open() ? static_cast<std::ostream&>(file_) : std::cout;
  out << j.dump() << "\n";
  out.flush();
}

sim::DriveOptions LoadDriveOptions(const std::string& config_path) {
  sim::DriveOptions options;
  if (config_path.empty()) return options;
  const io::YamlMap root = io::YamlMap::LoadFile(config_path);
  root.CheckKnownKeys({"render", "simulation", "drive"});
  if (root.Has("render")) {
    const io::YamlMap r = root.GetMap("render");
    r.CheckKnownKeys({"edge_supersample", "near_m", "far_m", "anisotropy"});
    auto& o = options.sim.render;
    o.edge_supersample = r.GetInt("edge_supersample", o.edge_supersample);
    o.near_m = r.GetDouble("near_m", o.near_m);
    o.far_m = r.GetDouble("far_m", o.far_m);
    o.anisotropy = r.GetDouble("anisotropy", o.anisotropy);
    try {
      o.Validate();
    } catch (const InputError& e) {
      r.Fail("", e.what());
    }
  }
  if (root.Has("simulation")) {
    const io::YamlMap s = root.GetMap("simulation");
    s.CheckKnownKeys({"physics_dt_s", "robot_body_height_m"});
    options.sim.physics_dt_s = s.GetDouble("physics_dt_s", options.sim.physics_dt_s);
    options.sim.robot_body_height_m =
        s.GetDouble("robot_body_height_m", options.sim.robot_body_height_m);
  }
  if (root.Has("drive")) {
    const io::YamlMap d = root.GetMap("drive");
    d.CheckKnownKeys({"timeout_factor", "stop_on_collision"});
    options.timeout_factor = d.GetDouble("timeout_factor", options.timeout_factor);
    options.stop_on_collision = d.GetBool("stop_on_collision", options.stop_on_collision);
  }
  try {
    options.Validate();
  } catch (const InputError& e) {
    throw InputError(config_path + ": " + e.what());
  }
  return options;
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

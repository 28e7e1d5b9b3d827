#include "mapless/robot/status.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

namespace mapless::robot {

std::vector<std::string> WrapText(const std::string& text, int max_width_px, int max_lines) {
  const auto width = [](const std::string& line) {
    int baseline = 0;
    return cv::getTextSize(line, cv::FONT_HERSHEY_PLAIN, 0.9, 1, &baseline).width;
  };
  std::vector<std::string> lines;
  std::string line;
  std::istringstream words(text);
  std::string word;
  while (words >> word) {
    const std::string longer = line.empty() ? word : line + " " + word;
    if (line.empty() || width(longer) <= max_width_px) {
      line = longer;
      continue;
    }
    lines.push_back(line);
    line = word;
  }
  if (!line.empty()) lines.push_back(line);
  for (std::string& l : lines)  // a single word wider than the picture: cut
    while (l.size() > 1 && width(l) > max_width_px) l.pop_back();
  if (static_cast<int>(lines.size()) > max_lines) {
    lines.resize(static_cast<std::size_t>(max_lines));
    std::string& last = lines.back();
    while (!last.empty() && width(last + "...") > max_width_px) last.pop_back();
    last += "...";
  }
  return lines;
}

std::string FixedText(double v, int digits) {
  std::ostringstream out;
  out.precision(digits);
  out << std::fixed << v;
  return out.str();
}

nlohmann::json StatusJson(const char* method, int frame, const Observation& observation,
                          const Decision& decision) {
  nlohmann::json j;
  j["frame"] = frame;
  j["t_s"] = ToSeconds(observation.t_ns);
  j["method"] = method;
  j["state"] = MethodStateName(decision.state);
  j["status"] = decision.status;
  if (!decision.reason.empty()) j["reason"] = decision.reason;
  j["v_mps"] = decision.command.v_mps;
  j["omega_radps"] = decision.command.omega_radps;
  if (decision.detail) decision.detail->Fields(&j);
  return j;
}

nlohmann::json StopJson(const char* method, Timestamp t_ns, const std::string& reason) {
  nlohmann::json j;
  j["t_s"] = ToSeconds(t_ns);
  j["method"] = method;
  j["state"] = "stopped";
  j["status"] = "stopped";
  j["reason"] = reason;
  j["v_mps"] = 0.0;
  j["omega_radps"] = 0.0;
  return j;
}

cv::Mat DebugImage(const Observation& observation, const Decision& decision) {
  cv::Mat grey =
      observation.image.empty() ? cv::Mat(240, 320, CV_8UC1, cv::Scalar(0)) : observation.image;
  const double scale = grey.cols < 320 ? 320.0 / grey.cols : 1.0;
  cv::Mat big;
  if (scale != 1.0) {
    cv::resize(grey, big, cv::Size(), scale, scale, cv::INTER_NEAREST);
  } else {
    big = grey;
  }
  cv::Mat out;
  cv::cvtColor(big, out, cv::COLOR_GRAY2BGR);
  const cv::Scalar green(0, 220, 0), red(0, 0, 255);
  std::vector<std::string> lines;
  if (decision.detail) decision.detail->Draw(&out, scale, &lines);
  lines.insert(lines.begin(), std::string(MethodStateName(decision.state)) + " (" +
                                  decision.status + ")  v " + FixedText(decision.command.v_mps, 2) +
                                  "  w " + FixedText(decision.command.omega_radps, 2));
  // Every line within the picture: the reason wrapped (at most 4 lines), the others wrapped too.
  std::vector<std::string> fitted;
  for (const std::string& line : lines)
    for (std::string& part : WrapText(line, out.cols - 8, 2)) fitted.push_back(std::move(part));
  if (!decision.reason.empty())
    for (std::string& part : WrapText(decision.reason, out.cols - 8, 4))
      fitted.push_back(std::move(part));
  int y = 14;
  for (const std::string& line : fitted) {
    cv::putText(out, line, cv::Point(4, y), cv::FONT_HERSHEY_PLAIN, 0.9, cv::Scalar(0, 0, 0), 3);
    cv::putText(out, line, cv::Point(4, y), cv::FONT_HERSHEY_PLAIN, 0.9,
                decision.state == MethodState::kDriving ? green : red, 1);
    y += 14;
  }
  return out;
}

}  // namespace mapless::robot

#include "mapless/robot/status.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <type_traits>

namespace mapless::robot {

namespace {

void PotentialFields(const navigation::PotentialStep& s, nlohmann::json* j) {
  (*j)["plane_found"] = s.plane_found;
  (*j)["plane_fraction"] = s.plane_fraction;
  (*j)["free_ahead"] = s.free_ahead;
  (*j)["theta_d_deg"] = RadToDeg(s.theta_d_rad);
  (*j)["theta_deg"] = RadToDeg(s.theta_rad);
  (*j)["force"] = {s.force[0], s.force[1]};
  (*j)["leg"] = s.leg;
}

void FollowerFields(const navigation::FollowerStep& s, nlohmann::json* j) {
  (*j)["index"] = s.index;
  (*j)["probability"] = s.probability;
  (*j)["target"] = s.target;
  if (s.carrying_on) (*j)["carrying_on"] = true;
  if (s.steering.ok) {
    (*j)["fit"] = s.steering.fit;
    (*j)["shift_px"] = s.steering.shift_px;
    (*j)["confidence"] = s.steering.confidence;
  }
  if (s.obstacle.observed) (*j)["obstacle_fraction"] = s.obstacle.blocked_fraction;
}

std::string Fixed(double v, int digits) {
  std::ostringstream out;
  out.precision(digits);
  out << std::fixed << v;
  return out.str();
}

}  // namespace

void RepeatFields(const navigation::RepeatStep& s, nlohmann::json* j) {
  (*j)["destination"] = s.destination;
  (*j)["matches"] = s.matches;
  (*j)["tracked"] = s.tracked;
  (*j)["switched"] = s.switched;
  if (s.recovered_from >= 0) (*j)["recovered_from"] = s.recovered_from;
  if (s.carrying_on) (*j)["carrying_on"] = true;
  if (s.avoiding) (*j)["avoiding"] = true;
  (*j)["std_ratio"] = s.switching.std_ratio;
  (*j)["ed_px"] = s.switching.ed_px;
  if (s.local_scale.ok) (*j)["local_scale"] = s.local_scale.ratio;
  (*j)["slope_x"] = s.sloped.slope_x;
  (*j)["slope_y"] = s.sloped.slope_y;
  if (s.obstacle.observed) (*j)["obstacle_fraction"] = s.obstacle.blocked_fraction;
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
  std::visit(
      [&](const auto& step) {
        using T = std::decay_t<decltype(step)>;
        if constexpr (std::is_same_v<T, navigation::RepeatStep>) RepeatFields(step, &j);
        if constexpr (std::is_same_v<T, navigation::PotentialStep>) PotentialFields(step, &j);
        if constexpr (std::is_same_v<T, navigation::FollowerStep>) FollowerFields(step, &j);
      },
      decision.detail);
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
  const cv::Scalar green(0, 220, 0), red(0, 0, 255), yellow(0, 220, 255), cyan(255, 255, 0);
  const cv::Point2d centre(out.cols / 2.0, out.rows / 2.0);
  std::vector<std::string> lines;
  std::visit(
      [&](const auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, navigation::RepeatStep>) {
          // Matched features, coloured by their side in the destination keyframe (the funnel
          // lanes' left and right sets), and a line to where each is in the keyframe.
          const float cx = static_cast<float>(grey.cols) / 2.0f;
          for (std::size_t i = 0; i < s.current_px.size(); ++i) {
            const cv::Point2f c = s.current_px[i] * scale;
            const bool left = i < s.destination_px.size() && s.destination_px[i].x < cx;
            if (i < s.destination_px.size())
              cv::line(out, c, s.destination_px[i] * scale, cv::Scalar(120, 120, 120), 1);
            cv::circle(out, c, 3, left ? green : cyan, 1, cv::LINE_AA);
          }
          lines.push_back("keyframe " + std::to_string(s.destination) + "  matches " +
                          std::to_string(s.matches) + "  tracked " + std::to_string(s.tracked));
          lines.push_back("slope_x " + Fixed(s.sloped.slope_x, 3) + "  slope_y " +
                          Fixed(s.sloped.slope_y, 3) + "  StdRatio " +
                          Fixed(s.switching.std_ratio, 2));
        }
        if constexpr (std::is_same_v<T, navigation::PotentialStep>) {
          if (!s.plane_mask.empty()) {
            cv::Mat mask;
            cv::resize(s.plane_mask, mask, out.size(), 0, 0, cv::INTER_NEAREST);
            cv::Mat tint(out.size(), CV_8UC3, green);
            cv::Mat blended;
            cv::addWeighted(out, 0.6, tint, 0.4, 0.0, blended);
            blended.copyTo(out, mask);
          }
          const double f = std::hypot(s.force[0], s.force[1]);
          if (f > 1e-9) {
            const double len = 0.3 * out.rows;
            const cv::Point2d tip =
                centre + cv::Point2d(s.force[0] / f * len, -s.force[1] / f * len);
            cv::arrowedLine(out, centre, tip, red, 2, cv::LINE_AA);
          }
          lines.push_back("plane " + Fixed(s.plane_fraction, 2) + "  ahead " +
                          Fixed(s.free_ahead, 2) + "  theta " + Fixed(RadToDeg(s.theta_rad), 1));
        }
        if constexpr (std::is_same_v<T, navigation::FollowerStep>) {
          lines.push_back("image " + std::to_string(s.index) + "  p " + Fixed(s.probability, 2) +
                          "  target " + std::to_string(s.target));
          if (s.steering.ok) {
            lines.push_back("fit " + s.steering.fit + "  shift " + Fixed(s.steering.shift_px, 1) +
                            " px  conf " + Fixed(s.steering.confidence, 2));
            const double x = centre.x + s.steering.shift_px * scale;
            cv::line(out, cv::Point2d(x, 0), cv::Point2d(x, out.rows), yellow, 1);
          }
        }
      },
      decision.detail);
  lines.insert(lines.begin(), std::string(MethodStateName(decision.state)) + " (" +
                                  decision.status + ")  v " + Fixed(decision.command.v_mps, 2) +
                                  "  w " + Fixed(decision.command.omega_radps, 2));
  if (!decision.reason.empty()) lines.push_back(decision.reason.substr(0, 60));
  int y = 14;
  for (const std::string& line : lines) {
    cv::putText(out, line, cv::Point(4, y), cv::FONT_HERSHEY_PLAIN, 0.9, cv::Scalar(0, 0, 0), 3);
    cv::putText(out, line, cv::Point(4, y), cv::FONT_HERSHEY_PLAIN, 0.9,
                decision.state == MethodState::kDriving ? green : red, 1);
    y += 14;
  }
  return out;
}

}  // namespace mapless::robot

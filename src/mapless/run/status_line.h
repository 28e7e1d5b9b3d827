// A live status line for a run on a robot or a recording: one line on standard error, rewritten in
// place at most five times a second, with the method's state, where it is on its route (keyframe,
// route image, leg), what it sees (matches, localization), the command and the distance driven.
// Quiet when standard error is not a terminal (logs, pipes, CI), so that logs stay as they were.
#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

namespace mapless::run {

// The line for one decision's status JSON (robot/status.h) after `driven_m` metres and
// `elapsed_s` seconds of the run, at most `width` characters: "repeat: driving | keyframe 12 |
// 85 matches | 0.20 m/s 0.05 rad/s | 3.4 m | 11.3 s".
std::string StatusLineText(const nlohmann::json& status, double driven_m, double elapsed_s,
                           std::size_t width = 99);

class StatusLine {
 public:
  // On when `wanted` and standard error is a terminal.
  explicit StatusLine(bool wanted = true);
  ~StatusLine();  // clears the line
  StatusLine(const StatusLine&) = delete;
  StatusLine& operator=(const StatusLine&) = delete;

  // One decision: accumulates the distance (the commanded speed over the time since the last
  // decision) and rewrites the line when 0.2 s have passed since the last time.
  void Show(const nlohmann::json& status);
  // Clears the line, so that a log line can be printed in its place.
  void Clear();
  bool enabled() const { return enabled_; }
  double driven_m() const { return driven_m_; }

 private:
  bool enabled_;
  bool shown_ = false;
  double driven_m_ = 0.0;
  double last_t_s_ = -1.0;
  double first_t_s_ = -1.0;  // a robot's stamps are its clock's (ROS time), not the run's
  std::chrono::steady_clock::time_point last_print_{};
};

}  // namespace mapless::run

#include "mapless/robot/loop.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mapless/core/check.h"

namespace mapless::robot {

void LoopOptions::Validate() const {
  MAPLESS_CHECK(max_speed_mps > 0.0,
                "LoopOptions.max_speed_mps = " << max_speed_mps << "; must be > 0");
  MAPLESS_CHECK(max_turn_rate_radps > 0.0,
                "LoopOptions.max_turn_rate_radps = " << max_turn_rate_radps << "; must be > 0");
  MAPLESS_CHECK(std::isfinite(max_frame_age_s) && max_frame_age_s >= 0.0,
                "LoopOptions.max_frame_age_s = " << max_frame_age_s << "; must be >= 0");
  MAPLESS_CHECK(
      std::isfinite(give_up_without_frames_s) && give_up_without_frames_s >= 0.0,
      "LoopOptions.give_up_without_frames_s = " << give_up_without_frames_s << "; must be >= 0");
  MAPLESS_CHECK(std::isfinite(max_blocked_s) && max_blocked_s >= 0.0,
                "LoopOptions.max_blocked_s = " << max_blocked_s << "; must be >= 0");
}

Twist2 LimitCommand(const Twist2& command, const LoopOptions& options) {
  Twist2 out = command;
  if (!std::isfinite(out.v_mps) || !std::isfinite(out.omega_radps)) return Twist2{};
  out.v_mps = std::clamp(out.v_mps, -options.max_speed_mps, options.max_speed_mps);
  out.omega_radps =
      std::clamp(out.omega_radps, -options.max_turn_rate_radps, options.max_turn_rate_radps);
  return out;
}

namespace {

std::string Seconds(double s) {
  std::ostringstream out;
  out.precision(2);
  out << std::fixed << s << " s";
  return out.str();
}

}  // namespace

LoopResult RunLoop(Method& method, RobotLink& link, const LoopOptions& options,
                   const LoopObserver& observer, const std::function<bool()>& interrupted) {
  options.Validate();
  LoopResult result;
  bool have_frame_time = false;
  Timestamp last_frame_ns = 0;
  bool blocked = false;  // by an obstacle, since blocked_since_ns
  Timestamp blocked_since_ns = 0;
  auto end = [&](bool finished, const std::string& reason) {
    result.finished = finished;
    result.failed = !finished;
    result.reason = reason;
    link.Stop(reason);
    return result;
  };
  while (true) {
    if (interrupted && interrupted()) return end(false, "interrupted");
    LinkEvent event = link.Next();
    if (interrupted && interrupted()) return end(false, "interrupted");
    switch (event.type) {
      case LinkEventType::kClosed:
        return end(false, event.reason.empty() ? "the robot link closed" : event.reason);
      case LinkEventType::kEStop:
        link.Stop(event.reason.empty() ? "emergency stop" : event.reason);
        continue;
      case LinkEventType::kNoFrame: {
        const double waited = have_frame_time ? ToSeconds(link.now_ns() - last_frame_ns) : 0.0;
        const std::string why = event.reason.empty() ? "no camera frame" : event.reason;
        if (options.give_up_without_frames_s > 0.0 && waited > options.give_up_without_frames_s)
          return end(false, why + " for " + Seconds(waited) + ": giving up");
        link.Stop(why);
        continue;
      }
      case LinkEventType::kFrame:
        break;
    }
    const Observation& obs = event.observation;
    have_frame_time = true;
    last_frame_ns = obs.t_ns;
    if (options.max_frame_age_s > 0.0) {
      const double age = ToSeconds(link.now_ns() - obs.t_ns);
      if (age > options.max_frame_age_s) {
        ++result.stale_frames;
        link.Stop("stale frame: " + Seconds(age) + " old (max_frame_age " +
                  Seconds(options.max_frame_age_s) + ")");
        continue;
      }
    }
    const cv::Size size = method.image_size();
    // An empty image (a dropped frame) goes to the method, whose camera check stops the robot.
    if (!obs.image.empty() &&
        (obs.image.type() != CV_8UC1 || (size.area() > 0 && obs.image.size() != size))) {
      std::ostringstream why;
      why << "frame " << obs.image.cols << "x" << obs.image.rows << " (type " << obs.image.type()
          << ") but " << method.name() << " needs 8-bit grey " << size.width << "x" << size.height;
      return end(false, why.str());
    }
    Decision decision = method.Step(obs);
    decision.command = LimitCommand(decision.command, options);
    ++result.frames;
    if (observer && !observer(obs, decision)) return end(true, "the run's goal was reached");
    if (decision.blocked && !blocked) blocked_since_ns = obs.t_ns;
    blocked = decision.blocked;
    if (blocked && options.max_blocked_s > 0.0 &&
        ToSeconds(obs.t_ns - blocked_since_ns) > options.max_blocked_s) {
      link.Send(Twist2{}, obs, decision);
      return end(false, "blocked for " + Seconds(ToSeconds(obs.t_ns - blocked_since_ns)) + " (" +
                            decision.reason +
                            "): clear the way and start again, or raise safety.max_blocked_s in "
                            "the robot file");
    }
    if (decision.done()) {
      link.Send(Twist2{}, obs, decision);  // the final decision reaches the status, with a zero
      return end(decision.state == MethodState::kFinished,
                 decision.reason.empty() ? decision.status : decision.reason);
    }
    if (std::string halted = link.Halted(); !halted.empty()) return end(false, halted);
    link.Send(decision.command, obs, decision);
  }
}

}  // namespace mapless::robot

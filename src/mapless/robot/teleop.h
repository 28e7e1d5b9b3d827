// Driving a robot from the keyboard (`mapless teleop`), as a method: the keys a person types are
// its input, so the one loop (loop.h) gives teleop every safety rule a method has (the robot
// file's speed limits, zero velocity without camera frames, on a stale frame, on the emergency
// stop and at the end). A terminal sends no key releases: a key's command holds while the key
// repeats and for `hold_s` after its last repeat, then the robot stops (as teleop_twist_keyboard's
// key timeout).
//
// Keys: w or Up forward, s or Down backward, a or Left turn left, d or Right turn right, q and e
// forward while turning left or right, space or x stop, + and - the speed up and down by a tenth
// of the robot's limits; Ctrl-C or Ctrl-D (or the end of the input) ends teleop.
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "mapless/core/pose.h"
#include "mapless/robot/method.h"

namespace mapless::robot {

struct TeleopOptions {
  double max_speed_mps = 0.3;        // the robot file's limits (REP-103)
  double max_turn_rate_radps = 1.0;  //
  double speed_fraction = 0.5;       // the starting speed, as a fraction of the limits
  double hold_s = 0.6;  // a key's command lasts this long after its last repeat (> the terminal's
                        // key-repeat delay, about 0.25-0.5 s)
  void Validate() const;
};

// The keys as commands: pure, with the time of each key given (seconds on any steady clock).
class TeleopKeys {
 public:
  explicit TeleopKeys(TeleopOptions options);
  // Bytes typed at time `t_s` (an arrow key's escape sequence may be split across calls).
  void Feed(std::string_view bytes, double t_s);
  // The command at `t_s`: the last motion key's, until hold_s after it; zero after that.
  Twist2 Command(double t_s) const;
  bool ended() const { return ended_; }  // Ctrl-C or Ctrl-D
  double speed_fraction() const { return fraction_; }

 private:
  void Key(char key, double t_s);
  TeleopOptions options_;
  double fraction_;
  double forward_ = 0.0;  // -1, 0 or 1
  double turn_ = 0.0;     // -1 (right) .. 1 (left)
  double last_key_s_ = -1e300;
  std::string pending_;  // an escape sequence not yet complete
  bool ended_ = false;
};

// What the keyboard gave since the last call: its bytes, and whether its input ended (the
// terminal closed, or the end of a file or pipe).
struct KeyInput {
  std::string bytes;
  bool closed = false;
};

class TeleopMethod : public Method {
 public:
  // `read` returns the keys typed since its last call without waiting; `now_s` is a steady clock
  // in seconds (empty: std::chrono::steady_clock's).
  TeleopMethod(TeleopOptions options, std::function<KeyInput()> read,
               std::function<double()> now_s = {});
  const char* name() const override { return "teleop"; }
  bool needs_odometry() const override { return false; }
  cv::Size image_size() const override { return {}; }
  Decision Step(const Observation& observation) override;

 private:
  TeleopKeys keys_;
  std::function<KeyInput()> read_;
  std::function<double()> now_s_;
  bool closed_ = false;
};

// The keys' help, one line.
const char* TeleopKeysHelp();

}  // namespace mapless::robot

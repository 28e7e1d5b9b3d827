#include "mapless/robot/teleop.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <utility>

#include "mapless/core/check.h"

namespace mapless::robot {
namespace {

constexpr char kCtrlC = 0x03;
constexpr char kCtrlD = 0x04;
constexpr char kEscape = 0x1b;

// The speed setting shown in the status and on the debug picture.
class TeleopDetail : public DecisionDetail {
 public:
  TeleopDetail(double fraction, Twist2 command) : fraction_(fraction), command_(command) {}
  void Fields(nlohmann::json* j) const override { (*j)["speed_fraction"] = fraction_; }
  void Draw(cv::Mat*, double, std::vector<std::string>* lines) const override {
    char text[64];
    std::snprintf(text, sizeof(text), "teleop %.0f%%: v %.2f m/s, w %.2f rad/s", 100.0 * fraction_,
                  command_.v_mps, command_.omega_radps);
    lines->push_back(text);
  }

 private:
  double fraction_;
  Twist2 command_;
};

}  // namespace

void TeleopOptions::Validate() const {
  MAPLESS_CHECK(max_speed_mps > 0.0 && max_speed_mps <= 10.0,
                "teleop: max_speed_mps = " << max_speed_mps << ": must be in (0, 10] m/s");
  MAPLESS_CHECK(
      max_turn_rate_radps > 0.0 && max_turn_rate_radps <= 10.0,
      "teleop: max_turn_rate_radps = " << max_turn_rate_radps << ": must be in (0, 10] rad/s");
  MAPLESS_CHECK(
      speed_fraction >= 0.1 && speed_fraction <= 1.0,
      "--speed-fraction " << speed_fraction << ": must be in [0.1, 1] (a fraction of the limits)");
  MAPLESS_CHECK(hold_s >= 0.1 && hold_s <= 5.0,
                "--hold " << hold_s << ": must be in [0.1, 5] seconds");
}

TeleopKeys::TeleopKeys(TeleopOptions options)
    : options_(options), fraction_(options.speed_fraction) {
  options_.Validate();
}

void TeleopKeys::Feed(std::string_view bytes, double t_s) {
  for (const char c : bytes) {
    if (!pending_.empty()) {
      pending_ += c;
      // ESC [ A..D: the arrows (ESC O A..D in the terminal's application mode).
      if (pending_.size() == 2 && c != '[' && c != 'O') {
        pending_.clear();
        Key(c, t_s);  // ESC then a plain key: the key
      } else if (pending_.size() == 3) {
        const char arrow = c;
        pending_.clear();
        if (arrow == 'A') Key('w', t_s);
        if (arrow == 'B') Key('s', t_s);
        if (arrow == 'C') Key('d', t_s);
        if (arrow == 'D') Key('a', t_s);
      }
      continue;
    }
    if (c == kEscape) {
      pending_ = std::string(1, c);
    } else {
      Key(c, t_s);
    }
  }
}

void TeleopKeys::Key(char key, double t_s) {
  double forward = 0.0;
  double turn = 0.0;
  switch (key) {
    case 'w':
    case 'W':
      forward = 1.0;
      break;
    case 's':
    case 'S':
      forward = -1.0;
      break;
    case 'a':
    case 'A':
      turn = 1.0;
      break;
    case 'd':
    case 'D':
      turn = -1.0;
      break;
    case 'q':
    case 'Q':
      forward = 1.0;
      turn = 0.5;
      break;
    case 'e':
    case 'E':
      forward = 1.0;
      turn = -0.5;
      break;
    case ' ':
    case 'x':
    case 'X':
      forward_ = turn_ = 0.0;
      last_key_s_ = -1e300;
      return;
    case '+':
    case '=':
      fraction_ = std::min(1.0, fraction_ + 0.1);
      return;
    case '-':
    case '_':
      fraction_ = std::max(0.1, fraction_ - 0.1);
      return;
    case kCtrlC:
    case kCtrlD:
      ended_ = true;
      return;
    default:
      return;  // any other key does nothing (and does not stop the robot either)
  }
  forward_ = forward;
  turn_ = turn;
  last_key_s_ = t_s;
}

Twist2 TeleopKeys::Command(double t_s) const {
  Twist2 c;
  if (ended_ || t_s - last_key_s_ > options_.hold_s) return c;
  c.v_mps = forward_ * fraction_ * options_.max_speed_mps;
  c.omega_radps = turn_ * fraction_ * options_.max_turn_rate_radps;
  return c;
}

TeleopMethod::TeleopMethod(TeleopOptions options, std::function<KeyInput()> read,
                           std::function<double()> now_s)
    : keys_(options), read_(std::move(read)), now_s_(std::move(now_s)) {
  if (!now_s_) {
    const auto start = std::chrono::steady_clock::now();
    now_s_ = [start] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
  }
}

Decision TeleopMethod::Step(const Observation&) {
  const double now = now_s_();
  if (!closed_) {
    KeyInput input = read_();
    keys_.Feed(input.bytes, now);
    closed_ = input.closed;
  }
  Decision d;
  if (keys_.ended() || closed_) {
    d.state = MethodState::kFinished;
    d.status = "ended";
    d.reason = keys_.ended() ? "ended from the keyboard" : "the keyboard's input ended";
    return d;
  }
  const Twist2 command = keys_.Command(now);
  d.detail = std::make_shared<TeleopDetail>(keys_.speed_fraction(), command);
  if (command.v_mps == 0.0 && command.omega_radps == 0.0) {
    d.state = MethodState::kStopped;
    d.status = "waiting for a key";
    d.reason = "no key held";
    return d;
  }
  d.state = MethodState::kDriving;
  d.status = "driving";
  d.command = command;
  return d;
}

const char* TeleopKeysHelp() {
  return "w/s or Up/Down forward/back, a/d or Left/Right turn, q/e forward turning, space stops, "
         "+/- speed, Ctrl-C or Ctrl-D ends";
}

}  // namespace mapless::robot

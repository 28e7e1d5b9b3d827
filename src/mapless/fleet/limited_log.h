// Log lines about what the network did (bad messages, peers joining, dropped or refused), at most
// one a second: a peer sending garbage, or 200 peers connecting, cannot flood the log. The lines
// held back are counted by kind and said in the next line, or by Flush() a second later.
// Internal to fleet/; one thread.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <utility>

#include "mapless/fleet/server.h"

namespace mapless::fleet {

class LimitedLog {
 public:
  explicit LimitedLog(FleetLogger log) : log_(std::move(log)) {}

  // `kind` counts the line when it is held back ("messages rejected", "followers joined").
  void Say(const std::string& kind, const std::string& line) {
    const auto now = Clock::now();
    if (said_ && now - last_ < std::chrono::seconds(1)) {
      ++held_[kind];
      return;
    }
    const std::string held = Held();
    Write(line + (held.empty() ? "" : " (held back since the last line: " + held + ")"));
    last_ = now;
    said_ = true;
  }
  // Says what was held back, once a second has passed since the last line.
  void Flush() {
    if (held_.empty() || Clock::now() - last_ < std::chrono::seconds(1)) return;
    Write("fleet: in the last second also " + Held());
    last_ = Clock::now();
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::string Held() {
    std::string text;
    for (const auto& [kind, n] : held_) {
      std::string what = kind;  // "followers joined"; one: "follower joined"
      const std::size_t space = what.find(' ');
      if (n == 1 && space != std::string::npos && space > 0 && what[space - 1] == 's')
        what.erase(space - 1, 1);
      text += (text.empty() ? "" : ", ") + std::to_string(n) + " " + what;
    }
    held_.clear();
    return text;
  }
  void Write(const std::string& line) {
    if (log_) log_(line);
  }

  FleetLogger log_;
  bool said_ = false;
  Clock::time_point last_{};
  std::map<std::string, int> held_;
};

}  // namespace mapless::fleet

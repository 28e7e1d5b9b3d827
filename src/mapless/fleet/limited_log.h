// Log lines about what the network did (bad messages, peers joining, dropped or refused), at most
// one a second of each kind: a peer sending garbage, or 200 peers connecting, cannot flood the log,
// and a follower joining does not hide why a message was refused in the same second. The kinds are
// the code's own few strings, never the network's. The lines held back are counted by kind and
// said with that kind's next line, or by Flush() a second later. Internal to fleet/; one thread.
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
    Kind& k = kinds_[kind];
    if (k.said && now - k.last < std::chrono::seconds(1)) {
      ++k.held;
      return;
    }
    const std::string held = Held(kind, &k);
    Write(line + (held.empty() ? "" : " (held back since the last such line: " + held + ")"));
    k.last = now;
    k.said = true;
  }
  // Says what was held back, for each kind whose last line is a second old.
  void Flush() {
    const auto now = Clock::now();
    for (auto& [name, k] : kinds_) {
      if (k.held == 0 || now - k.last < std::chrono::seconds(1)) continue;
      Write("fleet: in the last second also " + Held(name, &k));
      k.last = now;
    }
  }

 private:
  using Clock = std::chrono::steady_clock;
  struct Kind {
    bool said = false;
    Clock::time_point last{};
    int held = 0;
  };
  static std::string Held(const std::string& kind, Kind* k) {
    if (k->held == 0) return "";
    std::string what = kind;  // "followers joined"; one: "follower joined"
    const std::size_t space = what.find(' ');
    if (k->held == 1 && space != std::string::npos && space > 0 && what[space - 1] == 's')
      what.erase(space - 1, 1);
    const std::string text = std::to_string(k->held) + " " + what;
    k->held = 0;
    return text;
  }
  void Write(const std::string& line) {
    if (log_) log_(line);
  }

  FleetLogger log_;
  std::map<std::string, Kind> kinds_;
};

}  // namespace mapless::fleet

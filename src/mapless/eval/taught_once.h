// Test support: a scenario taught once per test binary (teaching is the slow part of the
// closed-loop tests). Later calls with the same name and variant get the same route.
#pragma once

#include <map>
#include <string>
#include <utility>

#include "mapless/eval/suite.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {

struct Taught {
  sim::Scenario scenario;
  TaughtRoute taught;
};

// `objects_stay`: the objects the repeat adds stay for the whole run (ObjectsStay).
inline const Taught& TaughtOnce(const std::string& scenario_name, bool objects_stay = false) {
  static std::map<std::pair<std::string, bool>, Taught> cache;
  const auto key = std::make_pair(scenario_name, objects_stay);
  auto it = cache.find(key);
  if (it == cache.end()) {
    sim::Scenario s = sim::LoadScenario(scenario_name);
    if (objects_stay) s.repeat_variant = ObjectsStay(s.repeat_variant);
    TaughtRoute t = TeachOnSimulator(s, navigation::TeachOptions{});
    it = cache.emplace(key, Taught{std::move(s), std::move(t)}).first;
  }
  return it->second;
}

}  // namespace mapless::eval

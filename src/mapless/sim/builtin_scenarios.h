// The built-in scenarios: config/scenarios/*.yaml compiled into the library by CMake
// (builtin_scenarios.cc is generated at configure time).
#pragma once

#include <cstddef>

namespace mapless::sim {

struct BuiltinScenario {
  const char* name;
  const char* text;
};

extern const BuiltinScenario kBuiltinScenarios[];
extern const std::size_t kBuiltinScenarioCount;

}  // namespace mapless::sim

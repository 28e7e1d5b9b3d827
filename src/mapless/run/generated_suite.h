// `mapless eval generated`: one method over N generated worlds (sim/generator.h), each run once
// (eval/generated.h): successes on the worlds labelled feasible, false stops and how long they
// lasted, collisions, stops before real obstacles, runs that ended without an answer, and the
// histogram of stop reasons. The world of every failure is written out with the one command that
// replays it.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "mapless/run/suites.h"

namespace mapless::run {

struct GeneratedSuiteOptions {
  int worlds = 50;  // world i: generated from seed + i, run with seed + i
  std::uint64_t seed = 1;
  std::string method = "funnel";         // funnel, eigenspace, potential
  std::string kind;                      // "" : each world's kind drawn from its seed
  std::vector<std::string> world_files;  // instead of generated worlds: these scenario files
  int jobs = 1;
  // A stop that does not clear ends a run after this long (the worlds' objects never leave, so a
  // stop before one would last for ever; a robot file's default is 60 s).
  double max_blocked_s = 30.0;
  bool watch = true;  // the obstacle watch (--on-obstacle stop); false: off, the papers' methods
  std::string failures_dir = "generated_failures";  // the failures' worlds go here
  std::string report_dir;                           // "" : no report
  std::function<void(int total)> on_start;
  std::function<void(const std::string& line)> on_entry_done;
};

SuiteOutput RunGeneratedSuite(const GeneratedSuiteOptions& options);

}  // namespace mapless::run

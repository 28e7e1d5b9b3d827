// The soak run (hardening): teach a route once, then repeat it lap after lap for a long simulated
// time (fast-forwarded: frames are computed as fast as the machine allows) in one simulator, one
// renderer and one route, so that anything that grows with the run shows. Each lap starts from
// the repeat start with a fresh repeat session, as a robot sent round its route again would.
// What must stay flat is judged by `mapless eval soak` (peak memory per lap, cost per frame).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "mapless/eval/teach_repeat.h"

namespace mapless::eval {

struct SoakOptions {
  std::string scenario = "table1_almost_straight";
  double duration_s = 3600.0;  // simulated time of repeating (the teach is not counted)
  RepeatRunOptions repeat;     // noise and controller of each lap (seed: the first lap's)
  void Validate() const;
};

struct SoakLap {
  int lap = 0;              // from 1
  double end_time_s = 0.0;  // simulated time at the end of the lap
  int frames = 0;
  bool completed = false;  // reached the end of the route
  bool collided = false;
  double final_error_m = 0.0;
  double median_frame_ms = 0.0;  // wall time of render + repeat step, per frame
  double p95_frame_ms = 0.0;
};

struct SoakSummary {
  int laps = 0;
  int completed_laps = 0;
  int frames = 0;
  double simulated_s = 0.0;
};

// Runs laps until duration_s of simulated time has passed; `on_lap` is called after each lap
// (the app measures memory there). `now_ms` is the clock that times each frame, passed in by the
// app (library code reads no clock); without one the frame costs are 0.
SoakSummary RunSoak(const SoakOptions& options, const std::function<void(const SoakLap&)>& on_lap,
                    const std::function<double()>& now_ms = {});

}  // namespace mapless::eval

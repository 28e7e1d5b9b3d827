// Routes that last (issue 45): a route taught on session 0 of a changing world (sim/sessions.h)
// and repeated on sessions 1, 2, ..., N in order, with experiences (each successful repeat's
// learned views written into the route, as `repeat --learn` does) or with the taught views alone.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mapless/eval/eigenspace.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {

// The changing-world scenarios `eval lifelong` runs by default: indoor, outdoor, a car park.
std::vector<std::string> LifelongScenarioNames();

struct LifelongOptions {
  int sessions = 20;  // repeated on sessions 1..sessions
  bool learn = true;  // experiences on (the route learns), or the taught views alone
  std::uint64_t seed = 1;
  RepeatRunOptions repeat;      // seed, learn and the speed are set per session
  EigenspaceRunOptions follow;  // RunLifelongFollow: seed, learn and the route are set per session
  void Validate() const;
};

// One repeat of one session.
struct LifelongSession {
  int session = 0;
  bool success = false;
  double lateral_rms_m = 0.0;
  int learned = 0;      // views learned on this session (written into the route when it succeeded)
  int route_views = 0;  // views in the route after this session (taught ones included)
  std::string status;
};

// One run: every session in order on one route.
struct LifelongRun {
  std::vector<LifelongSession> sessions;
  bool all_succeeded() const;
  int route_views = 0;     // after the last session, taught views included
  int route_features = 0;  // features over those views
};

// Repeats `taught` (taught on session 0 of `scenario`) on sessions 1..options.sessions of it.
LifelongRun RunLifelong(const sim::Scenario& scenario, const TaughtRoute& taught,
                        const LifelongOptions& options);

// The same for the appearance follower (`eval lifelong --method eigenspace`): `taught` (an
// eigenspace route taught on session 0) followed on sessions 1..options.sessions, with
// experiences (each arrived follow's learned views written into the route, as `follow --learn`
// does) or with the taught images alone. A session succeeds as `eval eigenspace`'s runs do
// (arrived within 0.6 m of the route's end, no collision); route_views counts the route's images
// and views, route_features 0.
LifelongRun RunLifelongFollow(const sim::Scenario& scenario, const TaughtAppearance& taught,
                              const LifelongOptions& options);

}  // namespace mapless::eval

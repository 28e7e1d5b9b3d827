#include "mapless/eval/lifelong.h"

#include <cmath>

#include "mapless/core/check.h"
#include "mapless/navigation/appearance_experiences.h"
#include "mapless/navigation/experiences.h"
#include "mapless/sim/sessions.h"

namespace mapless::eval {
namespace {

double LateralRms(const std::vector<Pose2>& taught, const std::vector<Pose2>& driven) {
  if (driven.empty()) return 0.0;
  double sum = 0.0;
  for (const Pose2& p : driven) {
    const double d = DistanceToPath(taught, p.x_m, p.y_m);
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(driven.size()));
}

int CountViews(const route::Route& route, int* features) {
  int views = 0;
  *features = 0;
  for (const route::Keyframe& k : route.keyframes) {
    views += 1 + static_cast<int>(k.views.size());
    *features += static_cast<int>(k.keypoints.size());
    for (const route::KeyframeView& v : k.views) *features += static_cast<int>(v.keypoints.size());
  }
  return views;
}

}  // namespace

std::vector<std::string> LifelongScenarioNames() {
  return {"lifelong_indoor", "lifelong_outdoor", "lifelong_car_park"};
}

void LifelongOptions::Validate() const {
  MAPLESS_CHECK(sessions >= 1 && sessions <= 1000,
                "sessions = " << sessions << "; must be in [1, 1000]");
  repeat.Validate();
}

bool LifelongRun::all_succeeded() const {
  for (const LifelongSession& s : sessions)
    if (!s.success) return false;
  return !sessions.empty();
}

LifelongRun RunLifelong(const sim::Scenario& scenario, const TaughtRoute& taught,
                        const LifelongOptions& options) {
  options.Validate();
  LifelongRun run;
  TaughtRoute route = taught;
  route.route = std::make_shared<route::Route>(*taught.route);
  for (int s = 1; s <= options.sessions; ++s) {
    const sim::Scenario session = sim::SessionScenario(scenario, s);
    RepeatRunOptions o = options.repeat;
    o.seed = options.seed * 1000 + static_cast<std::uint64_t>(s);
    o.repeat.learn = options.learn;
    const double speed = RepeatSpeedFor(scenario, o.max_repeat_speed_mps);
    o.repeat.sloped.max_speed_mps = speed;
    o.repeat.standard.forward_speed_mps = speed;
    const RepeatRun repeat = RepeatOnSimulator(session, route, o);
    LifelongSession row;
    row.session = s;
    row.success = repeat.success;
    row.status = repeat.status;
    row.lateral_rms_m = LateralRms(taught.path, repeat.path);
    row.learned = static_cast<int>(repeat.learned.size());
    // A route learns from a repeat that succeeded (`repeat --learn` writes nothing otherwise).
    if (options.learn && repeat.success) {
      auto learned = std::make_shared<route::Route>(*route.route);
      navigation::ApplyVisit(learned.get(), repeat.used_views, repeat.learned,
                             o.repeat.experiences);
      route.route = learned;
    }
    int features = 0;
    row.route_views = CountViews(*route.route, &features);
    run.sessions.push_back(row);
  }
  run.route_views = CountViews(*route.route, &run.route_features);
  return run;
}

LifelongRun RunLifelongFollow(const sim::Scenario& scenario, const TaughtAppearance& taught,
                              const LifelongOptions& options) {
  options.Validate();
  LifelongRun run;
  TaughtAppearance route = taught;
  const auto count = [](const route::StoredAppearanceRoute& r) {
    return static_cast<int>(r.images.size()) + r.views();
  };
  for (int s = 1; s <= options.sessions; ++s) {
    const sim::Scenario session = sim::SessionScenario(scenario, s);
    EigenspaceRunOptions o = options.follow;
    o.seed = options.seed * 1000 + static_cast<std::uint64_t>(s);
    o.follower.learn = options.learn;
    o.taught = &route;
    const EigenspaceRun follow = RunEigenspaceFollow(session, o);
    LifelongSession row;
    row.session = s;
    row.success = follow.success;
    row.status = follow.status;
    row.lateral_rms_m = LateralRms(taught.leader_path, follow.follower_path);
    row.learned = static_cast<int>(follow.learned.size());
    // A route learns from a follow that arrived (`follow --learn` writes nothing otherwise).
    if (options.learn && follow.success) {
      navigation::ApplyAppearanceVisit(&route.stored, follow.used_views, follow.learned,
                                       o.follower.experiences);
    }
    row.route_views = count(route.stored);
    run.sessions.push_back(row);
  }
  run.route_views = count(route.stored);
  return run;
}

}  // namespace mapless::eval

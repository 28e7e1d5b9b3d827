#include "mapless/eval/suite.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"
#include "mapless/navigation/experiences.h"

namespace mapless::eval {
namespace {

struct ObstacleStops {
  int stops = 0;                 // times the obstacle watch stopped the robot
  bool at_added_object = false;  // ... once while an object added at repeat time stood there
  double min_clearance_m = std::numeric_limits<double>::infinity();  // to the added objects
};

ObstacleStops CountObstacleStops(const sim::Scenario& scenario, const RepeatRun& run) {
  ObstacleStops out;
  const sim::World added = ObjectsAddedAtRepeat(scenario);
  const double period = 1.0 / scenario.camera.rate_hz;
  bool was_blocked = false;
  for (std::size_t i = 0; i < run.steps.size() && i < run.path.size(); ++i) {
    const sim::World now = sim::WorldAt(added, static_cast<double>(i) * period);
    const bool blocked = run.steps[i].status == navigation::RepeatStatus::kBlocked;
    if (blocked && !was_blocked) {
      ++out.stops;
      if (!now.objects.empty()) out.at_added_object = true;
    }
    was_blocked = blocked;
    if (!now.objects.empty()) {
      out.min_clearance_m =
          std::min(out.min_clearance_m, sim::ClearanceTo(now, run.path[i].x_m, run.path[i].y_m) -
                                            scenario.robot.radius_m);
    }
  }
  return out;
}

}  // namespace

sim::World ObjectsAddedAtRepeat(const sim::Scenario& scenario) {
  sim::World added;
  added.objects = scenario.repeat_variant.add;
  for (auto& o : added.objects) {
    const auto leaves = scenario.repeat_variant.leave_s.find(o.tag);
    if (!o.tag.empty() && leaves != scenario.repeat_variant.leave_s.end())
      o.leaves_s = leaves->second;
  }
  return added;
}

sim::WorldVariant ObjectsStay(sim::WorldVariant variant) {
  for (auto& o : variant.add) o.leaves_s = std::numeric_limits<double>::infinity();
  variant.leave_s.clear();
  return variant;
}

std::vector<std::string> SuiteNames() { return {"table1", "funnel-scenarios", "obstacles"}; }

std::vector<SuiteEntry> SuiteEntries(const std::string& suite) {
  std::vector<std::string> scenarios;
  if (suite == "table1") {
    scenarios = {"table1_sharp_turn_low_texture", "table1_almost_straight"};
  } else if (suite == "funnel-scenarios") {
    scenarios = {"narrow_room_sharp_turn",
                 "wide_left_turn_offset_start",
                 "corridor_25m",
                 "parking_between_cars",
                 "outdoor_loop_cars_removed",
                 "outdoor_wide_turn",
                 "indoor_30m",
                 "outdoor_70m",
                 "rotation_in_place"};
  } else if (suite == "obstacles") {
    // The standard lane too (2026-11-26): until then the watch never looked while it drove (its
    // turning alternates every frame, see ObstacleWatch::Update).
    return {{"obstacle_box_table1", navigation::Controller::kSloped},
            {"obstacle_box_table1", navigation::Controller::kStandard},
            {"obstacle_box_corridor", navigation::Controller::kSloped},
            {"obstacle_box_corridor", navigation::Controller::kStandard},
            {"obstacle_cylinder_outdoor", navigation::Controller::kSloped},
            {"obstacle_cylinder_outdoor", navigation::Controller::kStandard},
            {"keyframe_car_gone", navigation::Controller::kSloped},
            // Issue 42: objects that were in the taught views near the route's end, still there.
            {"end_before_chair", navigation::Controller::kSloped},
            {"end_before_cupboard", navigation::Controller::kSloped},
            {"end_before_bin_outdoor", navigation::Controller::kSloped}};
  } else {
    throw InputError("unknown suite '" + suite + "' (known: table1, funnel-scenarios, obstacles)");
  }
  std::vector<SuiteEntry> out;
  for (const auto& s : scenarios) {
    out.push_back({s, navigation::Controller::kSloped});
    out.push_back({s, navigation::Controller::kStandard});
  }
  return out;
}

EntryResult RunEntry(const sim::Scenario& scenario, const TaughtRoute& taught,
                     navigation::Controller controller, int runs, std::uint64_t seed,
                     const RepeatRunOptions& base, const RepeatObserver& first_run) {
  MAPLESS_CHECK(runs >= 1, "runs = " << runs << "; must be >= 1");
  EntryResult r;
  r.scenario = scenario.name;
  r.controller = navigation::ControllerName(controller);
  r.runs = runs;
  r.reference_path = taught.path;
  std::vector<double> finals;
  double lateral_sum_sq = 0.0;
  std::size_t lateral_count = 0;
  // With base.repeat.learn, the runs are one route's repeats in order: each successful run's
  // learned views go into the route the next run repeats (as `repeat --learn` writes them).
  TaughtRoute route = taught;
  for (int i = 0; i < runs; ++i) {
    RepeatRunOptions o = base;
    o.seed = seed + static_cast<std::uint64_t>(i);
    o.repeat.controller = controller;
    const double speed = RepeatSpeedFor(scenario, base.max_repeat_speed_mps);
    o.repeat.sloped.max_speed_mps = speed;
    o.repeat.standard.forward_speed_mps = speed;
    const RepeatRun run =
        RepeatOnSimulator(scenario, route, o, i == 0 ? first_run : RepeatObserver{});
    if (base.repeat.learn && run.success) {
      auto learned = std::make_shared<route::Route>(*route.route);
      r.learned +=
          navigation::ApplyVisit(learned.get(), run.used_views, run.learned, o.repeat.experiences);
      route.route = learned;
    }
    r.paths.push_back(run.path);
    finals.push_back(run.final_error_m);
    for (const Pose2& p : run.path) {
      const double d = DistanceToPath(taught.path, p.x_m, p.y_m);
      lateral_sum_sq += d * d;
      ++lateral_count;
    }
    if (run.success)
      ++r.successes;
    else
      r.failures.push_back("run " + std::to_string(i) + " (seed " + std::to_string(o.seed) +
                           "): " + run.status +
                           (run.completed && !run.collided
                                ? ", ended " + std::to_string(run.final_error_m).substr(0, 4) +
                                      " m from the taught end"
                                : ""));
    if (run.collided) ++r.collisions;
    if (run.completed && !run.collided)
      r.final_error_m_max = std::max(r.final_error_m_max, run.final_error_m);
    if (std::any_of(run.steps.begin(), run.steps.end(),
                    [](const navigation::RepeatStep& s) { return s.avoiding; }))
      ++r.went_round;
    const ObstacleStops stops = CountObstacleStops(scenario, run);
    if (stops.stops > 0) ++r.obstacle_stops;
    if (stops.at_added_object) ++r.stops_at_added_object;
    r.min_clearance_m = std::min(r.min_clearance_m, stops.min_clearance_m);
  }
  double sum_sq = 0.0;
  double sum = 0.0;
  for (double f : finals) {
    sum_sq += f * f;
    sum += f;
  }
  const double n = static_cast<double>(finals.size());
  r.final_error_m_rms = std::sqrt(sum_sq / n);
  const double mean = sum / n;
  double var = 0.0;
  for (double f : finals) var += (f - mean) * (f - mean);
  r.final_error_m_std = std::sqrt(var / n);
  r.lateral_rms_m =
      lateral_count > 0 ? std::sqrt(lateral_sum_sq / static_cast<double>(lateral_count)) : 0.0;
  return r;
}

}  // namespace mapless::eval

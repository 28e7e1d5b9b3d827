// `mapless lead`, `mapless follow --connect` and `mapless fleet keygen` (fleet.h).
#include "fleet.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <optional>
#include <thread>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/fleet/client.h"
#include "mapless/fleet/curve.h"
#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"
#include "mapless/io/atomic_file.h"
#include "mapless/robot/link_bench.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/robot_file.h"
#include "mapless/run/fleet_follow.h"
#include "mapless/run/leader_sink.h"
#include "mapless/run/learn.h"
#include "mapless/run/sim_episode.h"
#include "mapless/run/teach.h"
#include "robot_run.h"

namespace mapless::app {

namespace {

void FleetLog(const std::string& line) { spdlog::info("{}", line); }

struct LeadArgs {
  std::string source;
  std::string robot;
  std::string route;
  std::string bind;
  live::LiveArgs live;
  std::string method = "funnel";
  std::string detector = "orb";
  std::string curve_key;
  std::vector<std::string> curve_allow;
  double rate = 1.0;
  int take_views = 0;  // views per keyframe the route may hold with the followers' (0: none)
};

void Lead(const LeadArgs& a) {
  const fleet::RouteKind kind = run::ParseTeachMethod(a.method);
  if (a.source.empty() == a.robot.empty())
    throw InputError("lead: give one of --source sim:SCENARIO or --robot");
  if (!a.source.empty() && !run::IsSim(a.source))
    throw InputError("--source " + a.source + ": lead runs on sim:SCENARIO or --robot");
  features::ParseDetectorType(a.detector);
  if (a.take_views == 1 || (a.take_views > 0 && kind != fleet::RouteKind::kFunnel))
    throw InputError("--take-views " + std::to_string(a.take_views) +
                     ": a funnel route's keyframes hold their taught view and 1-63 more (2-64)");
  std::optional<sim::Scenario> scenario;
  if (run::IsSim(a.source)) {
    scenario = sim::LoadScenario(a.source.substr(4));
  } else {
    robot::LoadRobotFile(a.robot);  // refused before anything is served
  }
  fleet::ServerOptions server_options;
  server_options.bind = a.bind;
  server_options.security = fleet::LoadLeaderSecurity(a.curve_key, a.curve_allow);
  const auto live = OpenLive(a.live, "teach", false);  // refused before anything is made
  fleet::RouteCopy copy(a.route);                      // resumes an interrupted leader's route
  if (copy.header() && copy.header()->kind != kind)
    throw InputError(a.route + ": holds a " +
                     std::string(fleet::RouteKindName(copy.header()->kind)) +
                     " route; this leader teaches " + a.method);
  if (a.take_views > 0)
    server_options.take_view = [&copy, &a](const fleet::Record& r) {
      return copy.TakeView(r, a.take_views);
    };
  fleet::LeaderServer server(copy, server_options, FleetLog);
  spdlog::info("lead: serving {} on {}{}", a.route, server.endpoint(),
               server_options.security.enabled() ? " (CURVE)" : "");
  StopCleanlyOnInterrupt();
  run::LeaderSink sink(copy, server);
  run::TeacherOptions teacher_options;
  teacher_options.kind = kind;
  teacher_options.detector = a.detector;
  run::Teacher teacher(teacher_options, sink);
  const run::FrameTap tap = run::LiveTeachTap(live.get(), teacher);
  bool robot_teach_ended = false;
  if (copy.complete()) {
    spdlog::info("lead: {} is a complete route of {} records; serving it", a.route,
                 copy.next_sequence());
  } else {
    const auto skip = run::ResumeLeader(copy, kind, &teacher);
    if (copy.next_sequence() > 1)
      spdlog::info("lead: resuming the route in {} after record {}", a.route,
                   copy.next_sequence() - 1);
    run::TeachOutcome outcome;
    if (scenario) {
      run::Pacer pacer(a.rate);
      outcome = run::TeachOnSimulator(*scenario, teacher, tap, skip,
                                      [&pacer](Timestamp t_ns) { pacer.At(t_ns); });
    } else {
      run::LinkRequest request;
      request.warn = [](const std::string& m) { spdlog::warn("{}", m); };
      std::unique_ptr<robot::RobotLink> link = Links().Named("robot").open(a.robot, request);
      spdlog::info("lead: recording; drive the robot, Ctrl-C ends the route");
      outcome = run::TeachFromLink(*link, teacher, tap);
      // On a robot, Ctrl-C ends the route; a second one ends the leader.
      robot_teach_ended = outcome.interrupted;
    }
    if (outcome.failed) throw RunFailed("lead: " + outcome.end);
    if (outcome.interrupted && !robot_teach_ended) {
      spdlog::info("lead: interrupted after record {}; the route is kept for a resume",
                   copy.next_sequence() - 1);
      ThrowIfInterrupted();
    }
    teacher.Finish();
    spdlog::info("lead: route complete: {} records; serving it until Ctrl-C", copy.next_sequence());
  }
  while (true) {
    if (!robot_teach_ended) ThrowIfInterrupted();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

}  // namespace

namespace {

// The robot stays still (nothing is sent) until the route's header says what to follow and, for
// a copy resumed from disk, until the leader has confirmed it is the same route; what it waits for
// (no connection, a handshake failing) is said every 5 s.
void WaitForLeader(const fleet::RouteCopy& copy, const fleet::FollowerClient& client,
                   const FollowConnectArgs& a) {
  if (copy.next_sequence() > 0)
    spdlog::info("follow: waiting for the leader to confirm the copy in {}", a.route);
  auto next_word = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!copy.header() || !client.Verified()) {
    ThrowIfInterrupted();
    if (!client.Refusal().empty()) throw RunFailed("follow: " + client.Refusal());
    if (std::chrono::steady_clock::now() > next_word) {
      const fleet::ClientStats stats = client.stats();
      spdlog::info("follow: still waiting for the leader's route: {}",
                   stats.link_state.empty() ? "nothing heard from " + a.connect : stats.link_state);
      next_word += std::chrono::seconds(5);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// The follower on the simulator, in step with the wall clock; its summary for `eval fleet`.
void FollowOnSim(robot::Method& method, const sim::Scenario& scenario,
                 const fleet::RouteHeader& header, const fleet::RouteCopy& copy,
                 const fleet::FollowerClient& client, const FollowConnectArgs& a) {
  if (scenario.camera.model.width != header.image_width ||
      scenario.camera.model.height != header.image_height)
    throw InputError(a.source + ": the camera is " + std::to_string(scenario.camera.model.width) +
                     "x" + std::to_string(scenario.camera.model.height) +
                     ", the leader's route is " + std::to_string(header.image_width) + "x" +
                     std::to_string(header.image_height));
  run::SimRun sim(scenario,
                  run::FollowEpisode(scenario, header.kind, a.seed, a.motion_noise,
                                     /*live_leader=*/true),
                  a.rate);
  const std::vector<Pose2>& taught = sim.episode().taught;
  double lateral_sq = 0.0;
  int moving = 0;
  int waited = 0;  // frames stopped at the end of the route taught so far
  const auto live = OpenLive(a.live, method.name(), false);
  const run::RunOutcome outcome = RunOnSim(
      method, sim, a.log, nullptr,
      [&](const robot::Observation&, const robot::Decision& decision) {
        if (decision.reason.rfind("waiting for the leader", 0) == 0 ||
            decision.status == "waiting_for_leader")
          ++waited;
        if (decision.state == robot::MethodState::kDriving) {
          const double d = eval::DistanceToPath(taught, sim.truth().x_m, sim.truth().y_m);
          lateral_sq += d * d;
          ++moving;
        }
        return true;
      },
      live.get());
  const robot::LoopResult& result = outcome.loop;
  const bool success = sim.succeeded(result.finished);
  const fleet::ClientStats stats = client.stats();
  spdlog::info("follow: {} ({} frames); {:.2f} m from the route's end; {} records applied",
               result.reason, result.frames, sim.error_at_end_m(), stats.applied);
  if (!a.summary.empty()) {
    nlohmann::json j = fleet::ClientStatsJson(stats);
    j.update({{"completed", success},
              {"reason", result.reason},
              {"collided", sim.collided()},
              {"final_error_m", sim.error_at_end_m()},
              {"lateral_rms_m", moving > 0 ? std::sqrt(lateral_sq / moving) : 0.0},
              {"frames", result.frames},
              {"frames_waiting_for_leader", waited},
              {"copy_records", copy.next_sequence()}});
    io::WriteFileAtomic(a.summary, j.dump(1) + "\n");
  }
  if (!success) throw RunFailed("follow did not succeed: " + result.reason);
}

}  // namespace

void FollowConnected(const FollowConnectArgs& a) {
  if (a.source.empty() == a.robot.empty())
    throw InputError("follow: give one of --source sim:SCENARIO or --robot");
  if (!a.source.empty() && !run::IsSim(a.source))
    throw InputError("--source " + a.source + ": follow runs on sim:SCENARIO or --robot");
  if (a.curve_key.empty() != a.curve_leader.empty())
    throw InputError("--curve-key and --curve-leader go together");
  std::optional<sim::Scenario> scenario;
  if (run::IsSim(a.source)) scenario = sim::LoadScenario(a.source.substr(4));
  fleet::ClientOptions options;
  options.connect = a.connect;
  if (!a.curve_key.empty()) {
    options.security.key = fleet::LoadCurveKey(a.curve_key, true);
    options.security.leader_public = fleet::LoadCurveKey(a.curve_leader, false).public_key;
  }
  fleet::RouteCopy copy(a.route);
  if (copy.next_sequence() > 0)
    spdlog::info("follow: {} holds {} records of the route; asking for the rest", a.route,
                 copy.next_sequence());
  fleet::FollowerClient client(copy, options, FleetLog);
  StopCleanlyOnInterrupt();
  WaitForLeader(copy, client, a);
  const fleet::RouteHeader header = *copy.header();
  if (a.learn && header.kind != fleet::RouteKind::kFunnel)
    throw InputError("--learn: " + a.connect +
                     " serves an eigenspace route; views are learned "
                     "on funnel routes");
  run::FollowerSetup setup;
  setup.follower.obstacle =
      ObstacleWatchFor(a.robot, a.on_obstacle, setup.follower.obstacle, false);
  SetFollowerRecovery(a.carry_on_m, &setup.follower);
  setup.repeat.obstacle = ObstacleWatchFor(a.robot, a.on_obstacle, setup.repeat.obstacle, true);
  setup.repeat.carry_on.max_distance_m = a.carry_on_m;
  setup.repeat.learn = a.learn;
  const std::unique_ptr<robot::Method> method =
      run::FollowerMethod(header, copy, setup, scenario ? &*scenario : nullptr);
  spdlog::info("follow: a {} route from {}", fleet::RouteKindName(header.kind), a.connect);
  if (scenario) {
    FollowOnSim(*method, *scenario, header, copy, client, a);
  } else {
    SourceRunArgs args;
    args.log = a.log;
    args.robot = true;
    args.live = a.live;
    RunOnSource(*method, a.robot, args);
  }
  auto* repeat = dynamic_cast<robot::RepeatMethod*>(method.get());
  if (a.learn && repeat != nullptr && repeat->session())
    spdlog::info("follow: {}",
                 run::ShareLearnedViews(copy, client, repeat->session()->TakeLearned(), 10.0));
}

void AddLeadCommand(CLI::App* app) {
  auto a = std::make_shared<LeadArgs>();
  CLI::App* cmd = app->add_subcommand(
      "lead",
      "Teach a route and serve it to followers while teaching (ZeroMQ): funnel-lane keyframes or "
      "eigenspace route images. Restarted on the same --route, it resumes the route");
  cmd->add_option("--source", a->source, "sim:SCENARIO");
  cmd->add_option("--robot", a->robot, "Teach on a robot (a person drives): its robot file");
  cmd->add_option("--route", a->route, "Route directory (new, or an interrupted leader's)")
      ->required();
  AddLiveOption(cmd, &a->live, false);  // --real-time-factor paces it
  cmd->add_option("--bind", a->bind,
                  "Endpoint to serve on: tcp://ADDRESS:PORT (tcp://*:5600 for all interfaces), "
                  "ipc://PATH")
      ->required();
  cmd->add_option("--method", a->method, "funnel | eigenspace")->capture_default_str();
  cmd->add_option("--detector", a->detector, "funnel: feature detector")->capture_default_str();
  cmd->add_option("--real-time-factor", a->rate,
                  "Simulator: simulated seconds per second of wall clock (0: as fast as it can)")
      ->capture_default_str()
      ->check(ZeroOrIn(0.01, 100.0));
  AddOldName(cmd, "--rate", "--real-time-factor", &a->rate)->check(ZeroOrIn(0.01, 100.0));
  cmd->add_option("--take-views", a->take_views,
                  "Funnel: take the views followers learn (follow --connect --learn) into the "
                  "route, up to N per keyframe with the taught one (0: none; 2-64)")
      ->check(CLI::Range(0, 64));
  cmd->add_option("--curve-key", a->curve_key, "CURVE: the leader's key file (fleet keygen)");
  cmd->add_option("--curve-allow", a->curve_allow,
                  "CURVE: public key files of the followers admitted (default: any that has the "
                  "leader's public key)");
  cmd->callback([a] { Lead(*a); });
}

void AddFleetCommand(CLI::App* app) {
  CLI::App* fleet = app->add_subcommand("fleet", "Leader and follower tools");
  fleet->require_subcommand(1);
  auto path = std::make_shared<std::string>();
  CLI::App* keygen = fleet->add_subcommand(
      "keygen", "Make a CURVE key pair: FILE (secret, mode 0600) and FILE.pub (public)");
  keygen->add_option("FILE", *path, "Key file to write")->required();
  keygen->callback([path] {
    const fleet::CurveKey key = fleet::GenerateCurveKey(*path);
    spdlog::info("fleet keygen: {} (secret) and {}.pub (public key {})", *path, *path,
                 key.public_key);
  });
}

}  // namespace mapless::app

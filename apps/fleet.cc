// `mapless lead`, `mapless follow --connect` and `mapless fleet keygen` (fleet.h).
#include "fleet.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <thread>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/fleet/client.h"
#include "mapless/fleet/curve.h"
#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"
#include "mapless/io/atomic_file.h"
#include "mapless/navigation/teach.h"
#include "mapless/robot/link_bench.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/robot_file.h"
#include "mapless/robot/sim_link.h"
#include "mapless/robot/status.h"
#include "mapless/sim/simulation.h"
#include "robot_run.h"
#include "teach.h"

namespace mapless::app {

namespace {

void FleetLog(const std::string& line) { spdlog::info("{}", line); }

// Keeps a simulation in step with the wall clock: simulated time runs `rate` times as fast.
class Pacer {
 public:
  explicit Pacer(double rate) : rate_(rate) {}
  void At(Timestamp sim_ns) {
    if (rate_ <= 0.0) return;
    const auto now = std::chrono::steady_clock::now();
    if (!started_) {
      started_ = true;
      wall0_ = now;
      sim0_ = sim_ns;
      return;
    }
    const auto due = wall0_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(ToSeconds(sim_ns - sim0_) / rate_));
    if (due > now) std::this_thread::sleep_until(due);
  }

 private:
  double rate_;
  bool started_ = false;
  std::chrono::steady_clock::time_point wall0_;
  Timestamp sim0_ = 0;
};

// The simulator as a robot link in step with the wall clock (followers of a live leader).
class PacedLink : public robot::RobotLink {
 public:
  PacedLink(robot::SimLink& link, double rate) : link_(link), pacer_(rate) {}
  robot::LinkEvent Next() override {
    robot::LinkEvent e = link_.Next();
    pacer_.At(link_.now_ns());
    return e;
  }
  void Send(const Twist2& c, const robot::Observation& o, const robot::Decision& d) override {
    link_.Send(c, o, d);
  }
  void Stop(const std::string& reason) override { link_.Stop(reason); }
  std::string Halted() override { return link_.Halted(); }
  Timestamp now_ns() const override { return link_.now_ns(); }

 private:
  robot::SimLink& link_;
  Pacer pacer_;
};

fleet::LeaderSecurity LeaderKeys(const std::string& key, const std::vector<std::string>& allow) {
  fleet::LeaderSecurity security;
  if (key.empty()) {
    if (!allow.empty()) throw InputError("--curve-allow needs --curve-key (the leader's key)");
    return security;
  }
  security.key = fleet::LoadCurveKey(key, true);
  for (const std::string& file : allow)
    security.allowed_public.push_back(fleet::LoadCurveKey(file, false).public_key);
  return security;
}

// What a leader teaches: keyframes (funnel lanes) or route images (eigenspace), as records that
// its RouteCopy writes and its server serves.
class LeaderTeacher {
 public:
  LeaderTeacher(fleet::RouteCopy& copy, fleet::LeaderServer& server, fleet::RouteKind kind,
                const std::string& detector)
      : copy_(copy),
        server_(server),
        kind_(kind),
        detector_(detector),
        resuming_(copy.next_sequence() > 1 && !copy.complete()) {
    teach_options_.features.type = features::ParseDetectorType(detector);
    teach_options_.Validate();
    session_ = std::make_unique<navigation::TeachSession>(teach_options_);
    if (kind_ == fleet::RouteKind::kEigenspace && resuming_) {
      // Resume: the model as the interrupted leader had it.
      const route::StoredAppearanceRoute stored = route::LoadAppearanceRoute(copy_.dir());
      for (const auto& image : stored.images)
        leader_.AddStored(image.low, image.distance_m, image.odometry);
      last_resumed_ = stored.images.back().odometry;
    }
    if (kind_ == fleet::RouteKind::kFunnel && resuming_) {
      // The last stored keyframe's time (read back from its file).
      const std::vector<fleet::Record> last = copy_.RecordsFrom(copy_.next_sequence() - 1, 1);
      last_keyframe_t_ns_ = route::ParseKeyframe(last.at(0).parts.at(0), copy_.dir()).t_ns;
    }
  }
  bool resuming() const { return resuming_; }
  // Simulator resume: frames up to where the interrupted teach stopped are driven, not rendered.
  bool Skip(const sim::DriveFrame& f) {
    if (!resuming() || rendering_) return false;
    if (kind_ == fleet::RouteKind::kFunnel) {
      rendering_ = f.t_ns >= last_keyframe_t_ns_;
      drop_first_ = rendering_ && f.t_ns == last_keyframe_t_ns_;
      return !rendering_;
    }
    if (f.odometry.x_m == last_resumed_.x_m && f.odometry.y_m == last_resumed_.y_m &&
        f.odometry.theta_rad == last_resumed_.theta_rad) {
      rendering_ = true;  // from the next frame on
    }
    return true;
  }
  void Frame(const cv::Mat& image, Timestamp t_ns, const std::optional<Pose2>& odometry) {
    if (copy_.next_sequence() == 0) {
      fleet::RouteHeader h;
      h.kind = kind_;
      h.image_width = image.cols;
      h.image_height = image.rows;
      h.detector = detector_;
      navigation::AppearanceLeaderOptions appearance;
      h.low_width = appearance.image.width;
      h.low_height = appearance.image.height;
      Serve(fleet::HeaderRecord(h));
    }
    if (kind_ == fleet::RouteKind::kFunnel) {
      Keep(session_->Update(image, t_ns, odometry));
      return;
    }
    if (!odometry)
      throw InputError(
          "lead --method eigenspace needs wheel odometry (route images are spaced by "
          "distance): lead on sim:SCENARIO or on a robot with an odometry topic");
    if (leader_.Update(image, *odometry))
      Serve(fleet::ImageRecord({leader_.last_low(), leader_.distance_m(), *odometry}));
  }
  void Finish() {
    if (kind_ == fleet::RouteKind::kFunnel) Keep(session_->Finish());
    Serve(fleet::EndRecord());
  }
  int stored() const { return static_cast<int>(copy_.next_sequence()) - 1; }

 private:
  void Keep(std::optional<route::Keyframe> kf) {
    if (!kf) return;
    if (drop_first_) {  // the resumed session's first keyframe is the stored last one
      drop_first_ = false;
      return;
    }
    kf->index = static_cast<int>(copy_.next_sequence()) - 1;
    Serve(fleet::KeyframeRecord(*kf));
  }
  void Serve(fleet::Record record) {
    record.sequence = copy_.next_sequence();
    copy_.Apply({record});
    server_.Notify();
  }
  fleet::RouteCopy& copy_;
  fleet::LeaderServer& server_;
  fleet::RouteKind kind_;
  std::string detector_;
  navigation::TeachOptions teach_options_;
  std::unique_ptr<navigation::TeachSession> session_;
  navigation::AppearanceLeader leader_;
  bool resuming_;  // an interrupted leader's route was reloaded
  Pose2 last_resumed_;
  Timestamp last_keyframe_t_ns_ = 0;
  bool rendering_ = false;
  bool drop_first_ = false;
};

struct LeadArgs {
  std::string source;
  std::string robot;
  std::string route;
  std::string bind;
  std::string method = "funnel";
  std::string detector = "orb";
  std::string curve_key;
  std::vector<std::string> curve_allow;
  double rate = 1.0;
};

void Lead(const LeadArgs& a) {
  if (a.method != "funnel" && a.method != "eigenspace")
    throw InputError("--method " + a.method + ": must be funnel or eigenspace");
  const fleet::RouteKind kind = fleet::ParseRouteKind(a.method);
  if (a.source.empty() == a.robot.empty())
    throw InputError("lead: give one of --source sim:SCENARIO or --robot");
  if (!a.source.empty() && !IsSim(a.source))
    throw InputError("--source " + a.source + ": lead runs on sim:SCENARIO or --robot");
  features::ParseDetectorType(a.detector);
  std::optional<sim::Scenario> scenario;
  std::optional<robot::RobotFile> robot_file;
  if (IsSim(a.source)) {
    scenario = sim::LoadScenario(a.source.substr(4));
  } else {
    robot_file = robot::LoadRobotFile(a.robot);
  }
  fleet::ServerOptions server_options;
  server_options.bind = a.bind;
  server_options.security = LeaderKeys(a.curve_key, a.curve_allow);
  fleet::RouteCopy copy(a.route);  // resumes an interrupted leader's route
  if (copy.header() && copy.header()->kind != kind)
    throw InputError(a.route + ": holds a " +
                     std::string(fleet::RouteKindName(copy.header()->kind)) +
                     " route; this leader teaches " + a.method);
  fleet::LeaderServer server(copy, server_options, FleetLog);
  spdlog::info("lead: serving {} on {}{}", a.route, server.endpoint(),
               server_options.security.enabled() ? " (CURVE)" : "");
  StopCleanlyOnInterrupt();
  LeaderTeacher teacher(copy, server, kind, a.detector);
  bool robot_teach_ended = false;
  if (copy.complete()) {
    spdlog::info("lead: {} is a complete route of {} records; serving it", a.route,
                 copy.next_sequence());
  } else {
    if (teacher.resuming())
      spdlog::info("lead: resuming the route in {} after record {}", a.route,
                   copy.next_sequence() - 1);
    try {
      if (scenario) {
        Pacer pacer(a.rate);
        sim::DriveOptions drive;
        drive.skip_render = [&](const sim::DriveFrame& f) { return teacher.Skip(f); };
        const sim::DriveSummary summary =
            sim::DriveTaughtPath(*scenario, drive, [&](const sim::DriveFrame& f) {
              ThrowIfInterrupted();
              if (f.image.empty()) return;
              pacer.At(f.t_ns);
              teacher.Frame(f.image, f.t_ns, f.odometry);
            });
        if (!summary.completed)
          throw RunFailed("lead: the drive of '" + scenario->name +
                          "' did not complete: " + summary.status);
        teacher.Finish();
      } else {
        std::unique_ptr<robot::RobotLink> link = OpenRobotLink(*robot_file, {}, "teach");
        spdlog::info("lead: recording; drive the robot, Ctrl-C ends the route");
        try {
          while (true) {
            ThrowIfInterrupted();
            robot::LinkEvent e = link->Next();
            if (e.type == robot::LinkEventType::kClosed) {
              ThrowIfInterrupted();  // the link heard the interrupt first
              throw RunFailed("lead: " + e.reason);
            }
            if (e.type != robot::LinkEventType::kFrame) continue;
            teacher.Frame(e.observation.image, e.observation.t_ns, e.observation.odometry);
          }
        } catch (const Interrupted&) {
          teacher.Finish();  // on a robot, Ctrl-C ends the route; a second one ends the leader
          robot_teach_ended = true;
        }
      }
    } catch (const Interrupted&) {
      spdlog::info("lead: interrupted after record {}; the route is kept for a resume",
                   copy.next_sequence() - 1);
      throw;
    }
    spdlog::info("lead: route complete: {} records; serving it until Ctrl-C", copy.next_sequence());
  }
  while (true) {
    if (!robot_teach_ended) ThrowIfInterrupted();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

// The route a follower's method asks for; a route the leader completed too short to follow ends
// the run with the reason (waiting for more cannot help).
template <typename RoutePtr>
RoutePtr NotTooShort(const fleet::RouteCopy& copy, RoutePtr route, const char* unit, int minimum) {
  if (route == nullptr && copy.complete()) {
    const std::uint64_t n = copy.next_sequence() >= 2 ? copy.next_sequence() - 2 : 0;
    throw RunFailed("follow: the leader completed its route with " + std::to_string(n) + " " +
                    unit + "; a route to follow needs at least " + std::to_string(minimum));
  }
  return route;
}

}  // namespace

void FollowConnected(const FollowConnectArgs& a) {
  if (a.source.empty() == a.robot.empty())
    throw InputError("follow: give one of --source sim:SCENARIO or --robot");
  if (!a.source.empty() && !IsSim(a.source))
    throw InputError("--source " + a.source + ": follow runs on sim:SCENARIO or --robot");
  if (a.curve_key.empty() != a.curve_leader.empty())
    throw InputError("--curve-key and --curve-leader go together");
  std::optional<sim::Scenario> scenario;
  if (IsSim(a.source)) scenario = sim::LoadScenario(a.source.substr(4));
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
  // The robot stays still (nothing is sent) until the route's header says what to follow and,
  // for a copy resumed from disk, until the leader has confirmed it is the same route.
  if (copy.next_sequence() > 0)
    spdlog::info("follow: waiting for the leader to confirm the copy in {}", a.route);
  // Said every 5 s while nothing comes: what it waits for (no connection, a handshake failing).
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
  const fleet::RouteHeader header = *copy.header();
  const cv::Size size(header.image_width, header.image_height);
  std::unique_ptr<robot::Method> method;
  if (header.kind == fleet::RouteKind::kFunnel) {
    navigation::RepeatOptions repeat;
    repeat.features.type = features::ParseDetectorType(header.detector);
    repeat.obstacle = ObstacleWatchFor(a.robot, a.on_obstacle, repeat.obstacle, true);
    repeat.carry_on.max_distance_m = a.carry_on_m;
    if (scenario) {
      const double speed =
          eval::RepeatSpeedFor(*scenario, eval::RepeatRunOptions{}.max_repeat_speed_mps);
      repeat.sloped.max_speed_mps = speed;
      repeat.standard.forward_speed_mps = speed;
    }
    method = std::make_unique<robot::RepeatMethod>(
        [&copy] { return NotTooShort(copy, copy.FunnelRoute(), "keyframes", 2); }, repeat, size);
  } else {
    navigation::AppearanceFollowerOptions follower;
    follower.obstacle = ObstacleWatchFor(a.robot, a.on_obstacle, follower.obstacle, false);
    SetFollowerRecovery(a.carry_on_m, &follower);
    method = std::make_unique<robot::FollowMethod>(
        [&copy] { return NotTooShort(copy, copy.AppearanceRoute(), "route images", 1); }, follower,
        size);
  }
  spdlog::info("follow: a {} route from {}", fleet::RouteKindName(header.kind), a.connect);
  if (!scenario) {
    RunOnRobot(*method, a.robot, a.log);
    return;
  }
  if (scenario->camera.model.width != size.width || scenario->camera.model.height != size.height)
    throw InputError(a.source + ": the camera is " + std::to_string(scenario->camera.model.width) +
                     "x" + std::to_string(scenario->camera.model.height) +
                     ", the leader's route is " + std::to_string(size.width) + "x" +
                     std::to_string(size.height));
  eval::SimSetup setup;
  double timeout_s = 0.0;
  std::vector<Pose2> taught;
  sim::DriveOptions path_only;
  path_only.render_frames = false;
  const sim::DriveSummary drive = sim::DriveTaughtPath(
      *scenario, path_only, [&](const sim::DriveFrame& f) { taught.push_back(f.truth); });
  if (header.kind == fleet::RouteKind::kFunnel) {
    eval::RepeatRunOptions run;
    run.seed = a.seed;
    run.motion_noise_frac = a.motion_noise;
    setup = eval::RepeatSimSetup(*scenario, run);
    timeout_s = 2.0 * run.timeout_factor * std::max(drive.duration_s, 1.0);
  } else {
    eval::EigenspaceRunOptions run;
    run.seed = a.seed;
    run.motion_noise = a.motion_noise;
    setup = eval::FollowSimSetup(*scenario, run);
    timeout_s = 2.0 * eval::FollowTimeoutS(*scenario, run);
  }
  sim::Simulation sim(setup.world, setup.camera, {}, setup.seed);
  const int r = sim.AddRobot(setup.start, setup.robot);
  robot::SimLinkOptions link_options;
  link_options.period_s = 1.0 / scenario->camera.rate_hz;
  link_options.timeout_s = timeout_s;
  robot::SimLink sim_link(sim, r, link_options);
  PacedLink link(sim_link, a.rate);
  JsonLines log(a.log);
  int frame = 0;
  double lateral_sq = 0.0;
  int moving = 0;
  int waited = 0;  // frames stopped at the end of the route taught so far
  const robot::LoopResult result =
      robot::RunLoop(*method, link, robot::LoopOptions{},
                     [&](const robot::Observation& obs, const robot::Decision& decision) {
                       ThrowIfInterrupted();
                       const Pose2& truth = sim_link.truth();
                       if (decision.reason.rfind("waiting for the leader", 0) == 0 ||
                           decision.status == "waiting_for_leader")
                         ++waited;
                       if (decision.state == robot::MethodState::kDriving) {
                         const double d = eval::DistanceToPath(taught, truth.x_m, truth.y_m);
                         lateral_sq += d * d;
                         ++moving;
                       }
                       if (!a.log.empty()) {
                         nlohmann::json j = robot::StatusJson(method->name(), frame, obs, decision);
                         j["x_m"] = truth.x_m;
                         j["y_m"] = truth.y_m;
                         j["theta_rad"] = truth.theta_rad;
                         log.Write(j);
                       }
                       ++frame;
                       return true;
                     });
  const double final_error = sim_link.truth().DistanceTo(taught.back());
  const double tolerance = header.kind == fleet::RouteKind::kFunnel
                               ? eval::RepeatRunOptions{}.success_radius_m
                               : eval::EigenspaceRunOptions{}.arrive_tolerance_m;
  const bool success = result.finished && !sim.collided(r) && final_error <= tolerance;
  const fleet::ClientStats stats = client.stats();
  spdlog::info("follow: {} ({} frames); {:.2f} m from the route's end; {} records applied",
               result.reason, result.frames, final_error, stats.applied);
  if (!a.summary.empty()) {
    const std::vector<double>& latency = stats.latency_ms;
    const auto pct = [&](double p) {  // -1: no live records (the route was finished)
      return latency.empty() ? -1.0 : robot::Percentile(latency, p);
    };
    nlohmann::json j;
    j["completed"] = success;
    j["reason"] = result.reason;
    j["collided"] = sim.collided(r);
    j["final_error_m"] = final_error;
    j["lateral_rms_m"] = moving > 0 ? std::sqrt(lateral_sq / moving) : 0.0;
    j["frames"] = result.frames;
    j["frames_waiting_for_leader"] = waited;
    j["records_received"] = stats.received;
    j["records_applied"] = stats.applied;
    j["duplicates_dropped"] = stats.duplicates_dropped;
    j["ahead_dropped"] = stats.ahead_dropped;
    j["rejected"] = stats.rejected;
    j["subscriptions"] = stats.subscriptions;
    j["copy_records"] = copy.next_sequence();
    j["latency_samples"] = latency.size();
    j["latency_median_ms"] = pct(0.5);
    j["latency_p99_ms"] = pct(0.99);
    io::WriteFileAtomic(a.summary, j.dump(1) + "\n");
  }
  if (!success) throw RunFailed("follow did not succeed: " + result.reason);
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
  cmd->add_option("--bind", a->bind,
                  "Endpoint to serve on: tcp://ADDRESS:PORT (tcp://*:5600 for all interfaces), "
                  "ipc://PATH")
      ->required();
  cmd->add_option("--method", a->method, "funnel | eigenspace")->capture_default_str();
  cmd->add_option("--detector", a->detector, "funnel: feature detector")->capture_default_str();
  cmd->add_option("--rate", a->rate,
                  "Simulator: simulated seconds per second of wall clock (0: as fast as it can)")
      ->capture_default_str()
      ->check(ZeroOrIn(0.01, 100.0));
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

// `mapless sim serve`: the simulator as a ROS robot (ros1/sim_serve.h), set up like the robot of
// an evaluation run (--like) so that a run through ROS can be compared with the same run driven
// directly.
#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include "builtin_middlewares.h"
#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/robot/robot_file.h"
#include "mapless/robot/sim_serve.h"
#include "mapless/run/sim_episode.h"
#include "robot_run.h"

namespace mapless::app {

namespace {

struct ServeArgs {
  std::string scenario;
  std::string robot;
  std::string like = "teach";
  std::uint64_t seed = 1;
  double motion_noise = 0.1;
  double image_noise = 2.0;
  double timeout_s = 600.0;
  std::string summary;
  std::string encoding = "mono8";
  std::string size;
  live::LiveArgs live;
};

void Serve(const ServeArgs& a) {
  RefuseOutputOverInputs(a.summary, "--summary", {a.robot, a.scenario});
  const cv::Size size =
      a.size.empty() ? cv::Size() : io::ParseFrameSize(a.size, "--size", {16, 16});
  const robot::RobotFile file = robot::LoadRobotFile(a.robot);
  const sim::Scenario scenario = sim::LoadScenario(a.scenario);
  const eval::SimSetup setup =
      run::SimSetupLike(scenario, a.like, a.seed, a.motion_noise, a.image_noise);
  sim::Simulation sim(setup.world, setup.camera, {}, setup.seed);
  const int r = sim.AddRobot(setup.start, setup.robot);
  StopCleanlyOnInterrupt();
  robot::ServeOptions options;
  options.period_s = 1.0 / scenario.camera.rate_hz;
  options.timeout_s = a.timeout_s;
  options.interrupted = [] { return InterruptSignal() != 0; };
  options.log = [](const std::string& m) { spdlog::info("{}", m); };
  options.encoding = a.encoding;
  options.size = size;
  const auto live = OpenLive(a.live, "serve", false);
  options.on_step = live::ServedStep(live.get());
  const robot::ServeSummary s = BuiltinMiddlewares().For(file).serve(sim, r, file, options);
  spdlog::info("sim serve: {} after {} frames, {} commands{}, {:.1f} s simulated{}", s.end,
               s.frames, s.commands,
               s.resent > 0 ? ", " + std::to_string(s.resent) + " frames sent again" : "",
               s.sim_time_s, s.collided ? "; " + s.collision : "");
  if (!a.summary.empty()) {
    nlohmann::json j = robot::ServeSummaryJson(s);
    j.update({{"scenario", scenario.name},
              {"like", a.like},
              {"seed", a.seed},
              {"middleware", file.middleware}});
    io::WriteFileAtomic(a.summary, j.dump(2) + "\n");
  }
  ThrowIfInterrupted();
}

}  // namespace

void AddSimServeCommand(CLI::App* simcmd) {
  auto a = std::make_shared<ServeArgs>();
  CLI::App* cmd = simcmd->add_subcommand(
      "serve",
      "Serve a simulated robot over the robot file's middleware: camera, odometry and /clock "
      "out, cmd_vel in (lockstep in simulated time when the file sets use_sim_time)");
  cmd->add_option("--scenario", a->scenario, "Built-in scenario name or scenario YAML file")
      ->required();
  cmd->add_option("--robot", a->robot, "Robot file (YAML): topics, namespace, use_sim_time")
      ->required();
  cmd->add_option(
         "--like", a->like,
         "Set the robot up like a run of: teach (the teach start, no noise), repeat "
         "(the repeat start with a seeded offset and noise, as `mapless repeat`), "
         "navigate (the teach start and noise, as `mapless navigate`), follow (as `mapless "
         "follow`)")
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed (as in `mapless repeat --seed`)")
      ->capture_default_str()
      ->check(SeedCheck());
  cmd->add_option("--motion-noise", a->motion_noise, "Fraction of the command (repeat)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 0.9));
  cmd->add_option("--image-noise", a->image_noise, "Grey levels (repeat)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 100.0));
  AddLiveOption(cmd, &a->live, false);  // paced by the method or the clock
  cmd->add_option("--timeout", a->timeout_s, "Simulated seconds, then the serve ends")
      ->capture_default_str()
      ->check(FiniteIn(1.0, 86400.0));
  cmd->add_option("--encoding", a->encoding,
                  "Camera messages: mono8, rgb8, bgr8 (Image), jpeg, png (CompressedImage on "
                  "topics.compressed_image, or IMAGE/compressed)")
      ->capture_default_str();
  cmd->add_option("--size", a->size, "Publish the camera at WIDTHxHEIGHT (default: as simulated)");
  cmd->add_option("--summary", a->summary,
                  "Write the run's ground truth (pose at the method's last decision) as JSON here");
  cmd->callback([a] { Serve(*a); });
}

}  // namespace mapless::app

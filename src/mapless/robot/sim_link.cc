#include "mapless/robot/sim_link.h"

#include <cmath>

#include "mapless/core/check.h"

namespace mapless::robot {

void SimLinkOptions::Validate() const {
  MAPLESS_CHECK(std::isfinite(period_s) && period_s > 0.0,
                "SimLinkOptions.period_s = " << period_s << "; must be > 0");
  MAPLESS_CHECK(timeout_s > 0.0, "SimLinkOptions.timeout_s = " << timeout_s << "; must be > 0");
}

std::string SimulationStop(const sim::Simulation& sim, int robot, double timeout_s) {
  if (sim.collided(robot)) {
    for (const sim::Collision& c : sim.collisions())
      if (c.robot == robot) return "collision with " + c.with;
  }
  const double t = ToSeconds(sim.now_ns());
  if (t > timeout_s) return "timeout after " + std::to_string(static_cast<int>(t)) + " s";
  return {};
}

SimLink::SimLink(sim::Simulation& sim, int robot, SimLinkOptions options)
    : sim_(sim),
      robot_(robot),
      options_(std::move(options)),
      camera_(options_.camera_faults, options_.fault_seed) {
  options_.Validate();
  MAPLESS_CHECK(robot >= 0 && robot < sim.robot_count(), "SimLink: no robot " << robot);
}

LinkEvent SimLink::Next() {
  if (started_) sim_.Advance(options_.period_s);
  started_ = true;
  LinkEvent event;
  event.type = LinkEventType::kFrame;
  event.observation.t_ns = sim_.now_ns();
  event.observation.image = camera_.Apply(sim_.Render(robot_), ToSeconds(sim_.now_ns()));
  if (options_.odometry) event.observation.odometry = sim_.robot(robot_).odometry();
  return event;
}

void SimLink::Send(const Twist2& command, const Observation&, const Decision&) {
  sim_.SetCommand(robot_, command);
}

void SimLink::Stop(const std::string&) { sim_.SetCommand(robot_, Twist2{}); }

std::string SimLink::Halted() { return SimulationStop(sim_, robot_, options_.timeout_s); }

}  // namespace mapless::robot

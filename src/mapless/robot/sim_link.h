// The simulator as a robot link: one robot of a sim::Simulation, stepped in lockstep with the
// method. Next() advances the simulation by one camera period under the last command (not before
// the first frame) and renders the robot's camera; Halted() reports a collision or the timeout.
// Deterministic: the same simulation, seed and commands give the same frames.
#pragma once

#include <string>
#include <vector>

#include "mapless/robot/link.h"
#include "mapless/sim/camera_faults.h"
#include "mapless/sim/simulation.h"

namespace mapless::robot {

struct SimLinkOptions {
  double period_s = 0.1;   // one camera frame per period
  double timeout_s = 1e9;  // simulated time after which the run is halted
  bool odometry = true;    // frames carry the robot's wheel odometry
  std::vector<sim::CameraFaultWindow> camera_faults;  // injected camera faults (hardening)
  std::uint64_t fault_seed = 1;
  void Validate() const;
};

class SimLink : public RobotLink {
 public:
  // `sim` must outlive the link.
  SimLink(sim::Simulation& sim, int robot, SimLinkOptions options);

  LinkEvent Next() override;
  void Send(const Twist2& command, const Observation& observation,
            const Decision& decision) override;
  void Stop(const std::string& reason) override;
  std::string Halted() override;
  Timestamp now_ns() const override { return sim_.now_ns(); }
  std::optional<Pose2> GroundTruth() const override { return truth(); }

  const Pose2& truth() const { return sim_.robot(robot_).pose(); }  // ground truth now
  sim::Simulation& simulation() { return sim_; }
  int robot() const { return robot_; }

 private:
  sim::Simulation& sim_;
  int robot_;
  SimLinkOptions options_;
  sim::FaultyCamera camera_;
  bool started_ = false;
};

// Why a closed-loop run on the simulator must end now: "collision with ..." or "timeout after N s"
// (simulated time past timeout_s); empty while it may go on.
std::string SimulationStop(const sim::Simulation& sim, int robot, double timeout_s);

}  // namespace mapless::robot

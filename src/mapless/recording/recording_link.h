// Recording any run: a robot link that passes everything through to another link and records it
// (run_recorder.h): each camera frame with its odometry and, on the simulator, the true pose; each
// command sent and each stop as /cmd_vel; each decision as JSON. Put it between the loop and the
// link: robot::RunLoop(method, recording_link, ...).
#pragma once

#include <string>

#include "mapless/recording/run_recorder.h"
#include "mapless/robot/link.h"
#include "mapless/sim/camera.h"

namespace mapless::recording {

class RecordingLink : public robot::RobotLink {
 public:
  // `inner` and `recorder` must outlive the link; `method` names the decisions ("repeat", ...).
  RecordingLink(robot::RobotLink& inner, RunRecorder& recorder, std::string method);

  robot::LinkEvent Next() override;
  void Send(const Twist2& command, const robot::Observation& observation,
            const robot::Decision& decision) override;
  void Stop(const std::string& reason) override;
  std::string Halted() override { return inner_.Halted(); }
  Timestamp now_ns() const override { return inner_.now_ns(); }
  std::optional<Pose2> GroundTruth() const override { return inner_.GroundTruth(); }

 private:
  robot::RobotLink& inner_;
  RunRecorder& recorder_;
  std::string method_;
  int frame_ = 0;  // decisions recorded
  std::string last_stop_;
};

// The camera info of a pinhole camera without distortion (the simulator's).
rosmsg::CameraInfoFields CameraInfoOf(const sim::CameraModel& camera);

}  // namespace mapless::recording

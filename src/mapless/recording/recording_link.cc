#include "mapless/recording/recording_link.h"

#include "mapless/robot/status.h"

namespace mapless::recording {

RecordingLink::RecordingLink(robot::RobotLink& inner, RunRecorder& recorder, std::string method)
    : inner_(inner), recorder_(recorder), method_(std::move(method)) {}

robot::LinkEvent RecordingLink::Next() {
  robot::LinkEvent event = inner_.Next();
  if (event.type != robot::LinkEventType::kFrame) return event;
  const robot::Observation& obs = event.observation;
  if (!obs.image.empty() && obs.image.type() == CV_8UC1) recorder_.Image(obs.t_ns, obs.image);
  if (obs.odometry) recorder_.Odometry(obs.t_ns, *obs.odometry);
  if (const std::optional<Pose2> truth = inner_.GroundTruth())
    recorder_.GroundTruth(obs.t_ns, *truth);
  return event;
}

void RecordingLink::Send(const Twist2& command, const robot::Observation& observation,
                         const robot::Decision& decision) {
  inner_.Send(command, observation, decision);
  recorder_.Command(observation.t_ns, command);
  recorder_.Decision(observation.t_ns,
                     robot::StatusJson(method_.c_str(), frame_++, observation, decision));
  last_stop_.clear();
}

void RecordingLink::Stop(const std::string& reason) {
  inner_.Stop(reason);
  if (reason == last_stop_) return;  // a stop held over many events is recorded once
  last_stop_ = reason;
  const Timestamp t = inner_.now_ns();
  recorder_.Command(t, Twist2{});
  recorder_.Decision(t, robot::StopJson(method_.c_str(), t, reason));
}

rosmsg::CameraInfoFields CameraInfoOf(const sim::CameraModel& camera) {
  rosmsg::CameraInfoFields info;
  info.width = static_cast<std::uint32_t>(camera.width);
  info.height = static_cast<std::uint32_t>(camera.height);
  info.d = {0.0, 0.0, 0.0, 0.0, 0.0};
  info.k = {camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0};
  info.r = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.p = {camera.fx, 0.0, camera.cx, 0.0, 0.0, camera.fy, camera.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

}  // namespace mapless::recording

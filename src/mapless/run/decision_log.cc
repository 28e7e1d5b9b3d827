#include "mapless/run/decision_log.h"

#include <memory>

#include "mapless/robot/status.h"

namespace mapless::run {

namespace {

class LoggingLink : public robot::RobotLink {
 public:
  LoggingLink(robot::RobotLink& inner, std::unique_ptr<robot::RobotLink> owned, std::string method,
              JsonSink log)
      : inner_(owned ? *owned : inner),
        owned_(std::move(owned)),
        truth_(inner),
        method_(std::move(method)),
        log_(std::move(log)) {}
  robot::LinkEvent Next() override { return inner_.Next(); }
  void Send(const Twist2& command, const robot::Observation& obs,
            const robot::Decision& decision) override {
    nlohmann::json j = robot::StatusJson(method_.c_str(), frame_++, obs, decision);
    AddTruth(truth_.GroundTruth(), &j);
    log_(j);
    inner_.Send(command, obs, decision);
  }
  void Stop(const std::string& reason) override { inner_.Stop(reason); }
  std::string Halted() override { return inner_.Halted(); }
  Timestamp now_ns() const override { return inner_.now_ns(); }
  std::optional<Pose2> GroundTruth() const override { return truth_.GroundTruth(); }

 private:
  robot::RobotLink& inner_;
  std::unique_ptr<robot::RobotLink> owned_;
  robot::RobotLink& truth_;  // the innermost link: the simulator knows the true pose
  std::string method_;
  JsonSink log_;
  int frame_ = 0;
};

}  // namespace

void AddTruth(const std::optional<Pose2>& truth, nlohmann::json* j) {
  if (!truth) return;
  (*j)["x_m"] = truth->x_m;
  (*j)["y_m"] = truth->y_m;
  (*j)["theta_rad"] = truth->theta_rad;
}

robot::LinkWrapper LogDecisions(std::string method, JsonSink log, robot::LinkWrapper then) {
  if (!log) return then;
  return [method, log, then](robot::RobotLink& inner) -> std::unique_ptr<robot::RobotLink> {
    std::unique_ptr<robot::RobotLink> owned = then ? then(inner) : nullptr;
    return std::make_unique<LoggingLink>(inner, std::move(owned), method, log);
  };
}

}  // namespace mapless::run

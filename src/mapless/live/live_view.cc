#include "mapless/live/live_view.h"

namespace mapless::live {
namespace {

class LiveLink : public robot::RobotLink {
 public:
  LiveLink(std::unique_ptr<robot::RobotLink> owned, robot::RobotLink& inner, LiveView& view)
      : owned_(std::move(owned)), inner_(inner), view_(view) {}
  robot::LinkEvent Next() override { return inner_.Next(); }
  void Send(const Twist2& command, const robot::Observation& observation,
            const robot::Decision& decision) override {
    inner_.Send(command, observation, decision);
    view_.Frame(observation, decision, command, inner_.GroundTruth());
  }
  void Stop(const std::string& reason) override {
    inner_.Stop(reason);
    view_.Stopped(inner_.now_ns(), reason);
  }
  std::string Halted() override { return inner_.Halted(); }
  Timestamp now_ns() const override { return inner_.now_ns(); }
  std::optional<Pose2> GroundTruth() const override { return inner_.GroundTruth(); }

 private:
  std::unique_ptr<robot::RobotLink> owned_;  // the link `then` made, if any
  robot::RobotLink& inner_;
  LiveView& view_;
};

}  // namespace

LiveView::LiveView(std::string method, LiveViewOptions options) : method_(std::move(method)) {
  options.server.address = options.address;
  host_ = options.address.host;
  const bool has_route = !options.route.empty();
  server_ = std::make_unique<Server>(RunChannels(method_, has_route),
                                     std::make_unique<Feed>(std::move(options.route)), LivePage(),
                                     std::move(options.server));
}

void LiveView::Frame(const robot::Observation& observation, const robot::Decision& decision,
                     const Twist2& command, const std::optional<Pose2>& truth) {
  FrameView f;
  f.method = method_;
  f.frame = frame_++;
  f.observation.t_ns = observation.t_ns;
  f.observation.odometry = observation.odometry;
  // The image is copied only for a client: without one, only the pose goes on (the path).
  if (server_->clients() > 0) f.observation.image = observation.image.clone();
  f.decision = decision;
  f.command = command;
  f.truth = truth;
  last_stop_.clear();
  server_->Offer(std::move(f));
}

void LiveView::Stopped(Timestamp t_ns, const std::string& reason) {
  if (reason == last_stop_) return;
  last_stop_ = reason;
  FrameView f;
  f.method = method_;
  f.frame = frame_;
  f.observation.t_ns = t_ns;
  f.stop_reason = reason.empty() ? "stopped" : reason;
  server_->Offer(std::move(f));
}

std::string LiveView::url() const {
  const bool v6 = host_.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + host_ + "]" : host_) + ":" + std::to_string(port()) + "/";
}

robot::LinkWrapper LiveWrapper(LiveView* view, robot::LinkWrapper then) {
  if (view == nullptr) return then;
  return [view, then](robot::RobotLink& inner) -> std::unique_ptr<robot::RobotLink> {
    std::unique_ptr<robot::RobotLink> made = then ? then(inner) : nullptr;
    robot::RobotLink& next = made ? *made : inner;
    return std::make_unique<LiveLink>(std::move(made), next, *view);
  };
}

}  // namespace mapless::live

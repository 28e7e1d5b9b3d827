#include "mapless/live/live_view.h"

#include <thread>

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

LiveView::LiveView(std::string method, LiveViewOptions options)
    : method_(std::move(method)), pace_rate_(options.pace_rate) {
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
  Pace(observation.t_ns);
}

void LiveView::Pace(Timestamp t_ns) {
  using Clock = std::chrono::steady_clock;
  if (pace_rate_ <= 0.0 || server_->clients() == 0) {
    pace_origin_.reset();
    return;
  }
  const Clock::time_point now = Clock::now();
  if (!pace_origin_) pace_origin_.emplace(t_ns, now);
  const auto due = pace_origin_->second +
                   std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                       ToSeconds(t_ns - pace_origin_->first) / pace_rate_));
  if (due > now + std::chrono::seconds(1) || now > due + std::chrono::seconds(1)) {
    pace_origin_.emplace(t_ns, now);  // a jump in the clock or a slow stretch: start again here
  } else if (due > now) {
    std::this_thread::sleep_until(due);
  }
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

std::function<void(const robot::Observation&, const Twist2&, const Pose2&)> ServedStep(
    LiveView* view) {
  if (view == nullptr) return {};
  return [view](const robot::Observation& f, const Twist2& command, const Pose2& truth) {
    robot::Decision d;
    const bool moving = command.v_mps != 0.0 || command.omega_radps != 0.0;
    d.state = moving ? robot::MethodState::kDriving : robot::MethodState::kStopped;
    d.status = "served";
    d.command = command;
    view->Frame(f, d, command, truth);
  };
}

std::unique_ptr<LiveView> OpenLiveView(const LiveArgs& args, const char* method,
                                       std::vector<Pose2> route, bool simulated,
                                       const std::function<void(const std::string&)>& say) {
  if (args.address.empty()) return nullptr;
  LiveViewOptions options;
  options.address = ParseAddress(args.address);
  options.pace_rate = simulated ? args.rate : 0.0;
  options.route = std::move(route);
  options.server.log = say;
  auto view = std::make_unique<LiveView>(method, std::move(options));
  say("live view: " + view->url() +
      " in a browser; in Foxglove or Lichtblick open a Foxglove "
      "WebSocket connection to ws://" +
      view->url().substr(7));
  return view;
}

std::vector<Pose2> RoutePoses(const route::Route& route) {
  std::vector<Pose2> poses;
  for (const route::Keyframe& k : route.keyframes)
    if (k.odometry) poses.push_back(*k.odometry);
  return poses;
}

std::vector<Pose2> RoutePoses(const route::AppearanceRoute& route) {
  std::vector<Pose2> poses;
  for (const auto& image : route.images) poses.push_back(image->odometry);
  return poses;
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

// `--live [ADDRESS:]PORT` on a run: the live view (server.h) as one more link around the run's
// link, like a recording (recording/recording_link.h): every decision the loop sends, and every
// stop, is offered to the live view's server. The loop's own cost is a copy of the frame when a
// client is connected (nothing more without one); the rest happens on the server's thread.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mapless/live/server.h"
#include "mapless/robot/link.h"
#include "mapless/route/appearance_route.h"
#include "mapless/route/route.h"

namespace mapless::live {

// The page served at `/` (page.html, built into the program).
const std::string& LivePage();

// What a command's `--live` and `--live-rate` ask for.
struct LiveArgs {
  std::string address;  // [ADDRESS:]PORT; empty: no live view
  double rate = 1.0;    // the simulator, watched: simulated seconds per wall-clock second
};

struct LiveViewOptions {
  Address address;
  // > 0: while a client watches, the loop is held back to this many simulated seconds per
  // wall-clock second (the simulator runs faster than a person can follow). 0: never held back
  // (a robot, a recording: their clock is the wall clock already).
  double pace_rate = 0.0;
  std::vector<Pose2> route;  // the taught route in its teach's odometry frame (empty: none)
  ServerOptions server;      // its address is `address`
};

class LiveView {
 public:
  // Binds the address (InputError when it cannot), serves until destroyed.
  LiveView(std::string method, LiveViewOptions options);
  // What the loop decided on a frame (called from the loop's thread; returns at once).
  void Frame(const robot::Observation& observation, const robot::Decision& decision,
             const Twist2& command, const std::optional<Pose2>& truth);
  // A stop no frame decided (no camera, interrupted): said once per reason.
  void Stopped(Timestamp t_ns, const std::string& reason);
  int port() const { return server_->port(); }
  std::string url() const;  // "http://127.0.0.1:8765/"
  const Server& server() const { return *server_; }

 private:
  void Pace(Timestamp t_ns);

  std::string method_;
  std::string host_;
  std::unique_ptr<Server> server_;
  int frame_ = 0;
  std::string last_stop_;
  double pace_rate_ = 0.0;
  std::optional<std::pair<Timestamp, std::chrono::steady_clock::time_point>> pace_origin_;
};

// `sim serve`'s frames in the live view: each frame served with the command that answered it
// (status "served"); empty when `view` is null.
std::function<void(const robot::Observation&, const Twist2&, const Pose2&)> ServedStep(
    LiveView* view);

// A live view for a command's `--live ADDRESS` (null when it is empty), its address said through
// `say` with how to open it.
// `simulated`: the run is on the simulator (paced at args.rate while watched).
std::unique_ptr<LiveView> OpenLiveView(const LiveArgs& args, const char* method,
                                       std::vector<Pose2> route, bool simulated,
                                       const std::function<void(const std::string&)>& say);

// The taught route drawn under the robot: the keyframes' or route images' odometry (a funnel
// route taught without odometry has none).
std::vector<Pose2> RoutePoses(const route::Route& route);
std::vector<Pose2> RoutePoses(const route::AppearanceRoute& route);

// A link wrapper that shows the run in `view` around the link `then` makes (empty: none); empty
// when `view` is null.
robot::LinkWrapper LiveWrapper(LiveView* view, robot::LinkWrapper then = {});

}  // namespace mapless::live

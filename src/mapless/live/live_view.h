// `--live [ADDRESS:]PORT` on a run: the live view (server.h) as one more link around the run's
// link, like a recording (recording/recording_link.h): every decision the loop sends, and every
// stop, is offered to the live view's server. The loop's own cost is a copy of the frame when a
// client is connected (nothing more without one); the rest happens on the server's thread.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mapless/live/server.h"
#include "mapless/robot/link.h"

namespace mapless::live {

// The page served at `/` (page.html, built into the program).
const std::string& LivePage();

struct LiveViewOptions {
  Address address;
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
  std::string method_;
  std::string host_;
  std::unique_ptr<Server> server_;
  int frame_ = 0;
  std::string last_stop_;
};

// A link wrapper that shows the run in `view` around the link `then` makes (empty: none); empty
// when `view` is null.
robot::LinkWrapper LiveWrapper(LiveView* view, robot::LinkWrapper then = {});

}  // namespace mapless::live

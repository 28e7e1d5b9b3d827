// The half of a middleware adapter that does not depend on the middleware: what the receiving
// callbacks hand over (the newest camera frame, the odometry history, the e-stop, bad input) and
// the watchdog that turns their absence into a reason to stop. The ROS 1 and the ROS 2 adapters
// both keep one; each supplies its clock (the ROS clock: /clock under use_sim_time) and says
// whether the camera has a publisher.
//
// Callbacks may come from any thread; Next() is called by the loop's thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <set>
#include <string>

#include "mapless/robot/link.h"
#include "mapless/robot/robot_file.h"

namespace mapless::robot {

using Logger = std::function<void(const std::string&)>;

// Steady-clock nanoseconds (latencies).
std::int64_t SteadyNs();

struct InboxClock {
  std::function<Timestamp()> now;          // the ROS clock
  std::function<bool()> ok;                // false once the middleware shut down
  std::function<bool()> camera_published;  // false when no one publishes the camera
  // Why the middleware shut down, when ok() turned false (empty: "the middleware shut down").
  std::function<std::string()> closed_reason = {};
};

class FrameInbox {
 public:
  // `camera_topic` names the camera in the reasons; frames are turned upright and resized to
  // `size` (0x0: as they come) by Deliver().
  FrameInbox(const RobotFile& robot, cv::Size size, std::string camera_topic, Logger warn,
             InboxClock clock);

  // Starts the watchdog's clocks: call when receiving starts.
  void Start();

  // From the callbacks. A frame stamped 0 takes the clock's time; a frame with the stamp of the
  // one delivered last is a copy (a lockstep simulator sends a frame again when it suspects it was
  // lost) and is dropped.
  void Deliver(const cv::Mat& grey, Timestamp stamp_ns, std::int64_t received_steady_ns);
  void AddOdometry(Timestamp t_ns, const Pose2& pose);
  void SetEStop(bool engaged, const std::string& topic);
  // Bad input: said once per kind (to the logger), and named in the next stop's reason.
  void Warn(const std::string& kind, const std::string& message);

  // The newest frame, or why there is none (the link's Next()). Waits for one, hearing an
  // interrupt (core/interrupt.h: kClosed, "interrupted") within a few milliseconds. While the
  // e-stop is engaged, kEStop comes at once, then once per frame taken in (the frame dropped) or
  // per camera_timeout_s without frames: the stop it asks for goes out at most at the camera rate
  // plus the watchdog's.
  LinkEvent Next();
  // When the frame last returned by Next() was received (steady clock).
  std::int64_t received_steady_ns() const { return received_steady_ns_; }

 private:
  std::optional<Pose2> OdometryAt(Timestamp t_ns);
  std::string WhyNoFrame(const std::string& what) const;  // with the lock held

  RobotFile robot_;
  cv::Size size_;
  std::string camera_topic_;
  Logger warn_;
  InboxClock clock_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool have_frame_ = false;
  bool got_frame_ = false;
  cv::Mat frame_;
  Timestamp frame_t_ns_ = 0;
  Timestamp delivered_t_ns_ = -1;  // the stamp of the newest frame taken in
  std::int64_t frame_received_ns_ = 0;
  std::int64_t received_steady_ns_ = 0;
  std::deque<std::pair<Timestamp, Pose2>> odometry_;
  bool estop_ = false;
  bool estop_said_ = false;         // since it engaged
  std::int64_t estop_said_ns_ = 0;  // steady clock
  std::string estop_topic_;
  std::string bad_input_;
  std::set<std::string> warned_;
  Timestamp last_event_ns_ = 0;
  std::int64_t last_frame_steady_ns_ = 0;  // the last frame, or the start
};

}  // namespace mapless::robot

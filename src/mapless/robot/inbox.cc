#include "mapless/robot/inbox.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>

#include "mapless/core/interrupt.h"
#include "mapless/robot/camera_image.h"

namespace mapless::robot {

std::int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

FrameInbox::FrameInbox(const RobotFile& robot, cv::Size size, std::string camera_topic, Logger warn,
                       InboxClock clock)
    : robot_(robot),
      size_(size),
      camera_topic_(std::move(camera_topic)),
      warn_(std::move(warn)),
      clock_(std::move(clock)),
      last_frame_steady_ns_(SteadyNs()) {}

void FrameInbox::Start() {
  std::lock_guard<std::mutex> lock(mutex_);
  last_event_ns_ = clock_.now();
  last_frame_steady_ns_ = SteadyNs();
}

void FrameInbox::Deliver(const cv::Mat& grey, Timestamp stamp_ns, std::int64_t received_ns) {
  const bool stamped = stamp_ns != 0;
  const Timestamp t = stamped ? stamp_ns : clock_.now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stamped && t == delivered_t_ns_) return;  // a copy of the frame we have
  }
  cv::Mat frame = PrepareFrame(grey, robot_.mount, size_);
  std::lock_guard<std::mutex> lock(mutex_);
  frame_ = frame;
  frame_t_ns_ = t;
  delivered_t_ns_ = t;
  frame_received_ns_ = received_ns;
  have_frame_ = true;
  bad_input_.clear();
  cv_.notify_all();
}

void FrameInbox::AddOdometry(Timestamp t_ns, const Pose2& pose) {
  std::lock_guard<std::mutex> lock(mutex_);
  odometry_.emplace_back(t_ns, pose);
  while (odometry_.size() > 200) odometry_.pop_front();
  cv_.notify_all();
}

void FrameInbox::SetEStop(bool engaged, const std::string& topic) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (engaged != estop_) estop_said_ = false;  // a new e-stop is said at once
  estop_ = engaged;
  estop_topic_ = topic;
  cv_.notify_all();
}

void FrameInbox::Warn(const std::string& kind, const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  bad_input_ = message;
  if (!warned_.insert(kind).second) return;
  if (warn_) warn_(message + " (said once)");
}

std::string FrameInbox::WhyNoFrame(const std::string& what) const {
  std::string why = what;
  if (clock_.camera_published && !clock_.camera_published()) why += " (no publisher)";
  if (!bad_input_.empty()) why += " (" + bad_input_ + ")";
  return why;
}

LinkEvent FrameInbox::Next() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    if (clock_.ok && !clock_.ok())
      return {LinkEventType::kClosed,
              {},
              clock_.closed_reason ? clock_.closed_reason() : "the middleware shut down"};
    if (InterruptRequested()) return {LinkEventType::kClosed, {}, "interrupted"};
    if (estop_) {
      // Said when it engages, then once per camera frame (each frame taken in is dropped and
      // answered with a stop, as a lockstep simulator expects an answer per frame) and, without
      // frames, once per camera_timeout_s: never as fast as the loop can turn (issue 40).
      const std::int64_t steady = SteadyNs();
      const double since_s = ToSeconds(steady - estop_said_ns_);
      if (!estop_said_ || have_frame_ || since_s >= std::max(robot_.camera_timeout_s, 0.05)) {
        have_frame_ = false;
        estop_said_ = true;
        estop_said_ns_ = steady;
        return {LinkEventType::kEStop, {}, "emergency stop (" + estop_topic_ + ")"};
      }
      cv_.wait_for(lock, std::chrono::milliseconds(5));
      continue;
    }
    if (have_frame_) {
      have_frame_ = false;
      got_frame_ = true;
      last_frame_steady_ns_ = SteadyNs();
      LinkEvent event{LinkEventType::kFrame, {}, {}};
      event.observation.image = frame_;
      event.observation.t_ns = frame_t_ns_;
      received_steady_ns_ = frame_received_ns_;
      lock.unlock();
      event.observation.odometry = OdometryAt(event.observation.t_ns);
      // The watchdog counts from the newest of the frame's stamp and its arrival: the clock
      // and the frame come on different connections, in either order.
      const Timestamp now = clock_.now();
      lock.lock();
      last_event_ns_ = std::max({last_event_ns_, now, event.observation.t_ns});
      return event;
    }
    const Timestamp now = clock_.now();
    // Giving up is on the wall clock: under use_sim_time a simulator that no frame reaches us
    // from may never advance the ROS clock.
    const double without_s = ToSeconds(SteadyNs() - last_frame_steady_ns_);
    if (robot_.give_up_without_frames_s > 0.0 && without_s > robot_.give_up_without_frames_s) {
      return {LinkEventType::kClosed,
              {},
              WhyNoFrame("no usable camera frame on " + camera_topic_ + " for " +
                         std::to_string(static_cast<int>(without_s)) + " s: giving up")};
    }
    // A frame may arrive before the /clock message of its time, so the clock lags the last frame
    // by a period or so; only a jump back of more than a second (a restarted simulation, a
    // replay looping) resets the watchdog's reference.
    if (now + kNsPerSecond < last_event_ns_) last_event_ns_ = now;
    // Before the first frame the camera has connect_timeout_s to appear (the robot is stopped
    // anyway); a zero Twist then would also be taken as the answer to a lockstep simulator's
    // first frame.
    const double timeout = got_frame_ ? robot_.camera_timeout_s
                                      : std::max(robot_.camera_timeout_s, robot_.connect_timeout_s);
    if (ToSeconds(now - last_event_ns_) >= timeout) {
      last_event_ns_ = now;
      return {LinkEventType::kNoFrame,
              {},
              WhyNoFrame("no camera frame on " + camera_topic_ + " for " +
                         std::to_string(timeout).substr(0, 4) + " s")};
    }
    cv_.wait_for(lock, std::chrono::milliseconds(5));
  }
}

// The odometry at a frame's time: the message nearest to it. Under use_sim_time (a lockstep
// simulator publishes the odometry of each frame's time with it) it first waits briefly (wall
// time) for one stamped at or after the frame, so that the two pair up whichever arrives first;
// in real time it takes the nearest it has, adding no latency.
std::optional<Pose2> FrameInbox::OdometryAt(Timestamp t_ns) {
  if (robot_.topics.odometry.empty()) return std::nullopt;
  std::unique_lock<std::mutex> lock(mutex_);
  if (robot_.use_sim_time) {
    cv_.wait_for(lock, std::chrono::milliseconds(50),
                 [&] { return !odometry_.empty() && odometry_.back().first >= t_ns; });
  }
  if (odometry_.empty()) return std::nullopt;
  const std::pair<Timestamp, Pose2>* best = &odometry_.back();
  for (const auto& o : odometry_)
    if (std::llabs(o.first - t_ns) < std::llabs(best->first - t_ns)) best = &o;
  return best->second;
}

}  // namespace mapless::robot

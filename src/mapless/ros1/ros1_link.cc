#include "mapless/ros1/ros1_link.h"

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Bool.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/robot/camera_image.h"
#include "mapless/robot/status.h"

namespace mapless::ros1 {

namespace {

using SteadyClock = std::chrono::steady_clock;

std::int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now().time_since_epoch())
      .count();
}

Timestamp ToNs(const ros::Time& t) { return static_cast<Timestamp>(t.toNSec()); }

double Yaw(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

}  // namespace

void StartNode(const robot::RobotFile& robot, const std::string& node_name) {
  if (ros::isInitialized()) return;
  std::map<std::string, std::string> remappings;
  if (!robot.ns.empty()) remappings["__ns"] = robot.ns;
  ros::init(remappings, node_name, ros::init_options::NoSigintHandler);
  const auto deadline = SteadyClock::now() + std::chrono::duration<double>(robot.connect_timeout_s);
  while (!ros::master::check()) {
    if (SteadyClock::now() > deadline) {
      throw std::runtime_error("no ROS master at " + ros::master::getURI() + " after " +
                               std::to_string(static_cast<int>(robot.connect_timeout_s)) +
                               " s: start roscore or set ROS_MASTER_URI");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (robot.use_sim_time) ros::param::set("/use_sim_time", true);
  ros::start();
}

class Ros1Link::Impl {
 public:
  Impl(const robot::RobotFile& robot, cv::Size size, std::string method, Logger warn)
      : robot_(robot),
        size_(size),
        method_(std::move(method)),
        warn_(std::move(warn)),
        spinner_(1) {
    ros::NodeHandle nh;
    const std::string image_topic = robot.topics.compressed_image.empty()
                                        ? robot.Resolve(robot.topics.image)
                                        : robot.Resolve(robot.topics.compressed_image);
    camera_topic_ = image_topic;
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    if (robot.topics.compressed_image.empty()) {
      image_sub_ = nh.subscribe(image_topic, 2, &Impl::OnImage, this, hints);
    } else {
      image_sub_ = nh.subscribe(image_topic, 2, &Impl::OnCompressed, this, hints);
    }
    if (!robot.topics.odometry.empty())
      odom_sub_ =
          nh.subscribe(robot.Resolve(robot.topics.odometry), 50, &Impl::OnOdometry, this, hints);
    if (!robot.topics.estop.empty())
      estop_sub_ = nh.subscribe(robot.Resolve(robot.topics.estop), 5, &Impl::OnEStop, this, hints);
    cmd_pub_ = nh.advertise<geometry_msgs::Twist>(robot.Resolve(robot.topics.cmd_vel), 10);
    status_pub_ = nh.advertise<std_msgs::String>(robot.Resolve(robot.topics.status), 10);
    if (!robot.topics.debug_image.empty())
      debug_pub_ = nh.advertise<sensor_msgs::Image>(robot.Resolve(robot.topics.debug_image), 2);
  }

  void Start() {
    spinner_.start();
    last_event_ns_ = ToNs(ros::Time::now());
    last_frame_steady_ns_ = SteadyNs();
  }

  ~Impl() {
    // A link that ever commanded the robot leaves it at zero velocity; one that only listened
    // (teaching: a person drives) publishes nothing.
    if (commanded_) {
      PublishTwist(Twist2{});
      // Give the zero Twist time to leave before the connections close.
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    spinner_.stop();
  }

  robot::LinkEvent Next() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      if (!ros::ok()) return {robot::LinkEventType::kClosed, {}, "ROS shut down"};
      if (estop_)
        return {robot::LinkEventType::kEStop, {}, "emergency stop (" + estop_topic() + ")"};
      if (have_frame_) {
        have_frame_ = false;
        got_frame_ = true;
        last_frame_steady_ns_ = SteadyNs();
        robot::LinkEvent event{robot::LinkEventType::kFrame, {}, {}};
        event.observation.image = frame_;
        event.observation.t_ns = frame_t_ns_;
        received_steady_ns_ = frame_received_ns_;
        lock.unlock();
        event.observation.odometry = OdometryAt(event.observation.t_ns);
        // The watchdog counts from the newest of the frame's stamp and its arrival: the clock
        // and the frame come on different connections, in either order.
        last_event_ns_ = std::max({last_event_ns_, ToNs(ros::Time::now()), event.observation.t_ns});
        return event;
      }
      const Timestamp now = ToNs(ros::Time::now());
      // Giving up is on the wall clock: under use_sim_time a simulator that no frame reaches us
      // from may never advance the ROS clock.
      const double without_s = ToSeconds(SteadyNs() - last_frame_steady_ns_);
      if (robot_.give_up_without_frames_s > 0.0 && without_s > robot_.give_up_without_frames_s) {
        std::string why = "no usable camera frame on " + camera_topic_ + " for " +
                          std::to_string(static_cast<int>(without_s)) + " s: giving up";
        if (image_sub_.getNumPublishers() == 0) why += " (no publisher)";
        if (!bad_input_.empty()) why += " (" + bad_input_ + ")";
        return {robot::LinkEventType::kClosed, {}, why};
      }
      // A frame may arrive before the /clock message of its time, so the clock lags the last frame
      // by a period or so; only a jump back of more than a second (a restarted simulation, a
      // replay looping) resets the watchdog's reference.
      if (now + kNsPerSecond < last_event_ns_) last_event_ns_ = now;
      // Before the first frame the camera has connect_timeout_s to appear (the robot is stopped
      // anyway); a zero Twist then would also be taken as the answer to a lockstep simulator's
      // first frame.
      const double timeout = got_frame_
                                 ? robot_.camera_timeout_s
                                 : std::max(robot_.camera_timeout_s, robot_.connect_timeout_s);
      if (ToSeconds(now - last_event_ns_) >= timeout) {
        last_event_ns_ = now;
        std::string why = "no camera frame on " + camera_topic_ + " for " +
                          std::to_string(timeout).substr(0, 4) + " s";
        if (image_sub_.getNumPublishers() == 0) why += " (no publisher)";
        if (!bad_input_.empty()) why += " (" + bad_input_ + ")";
        return {robot::LinkEventType::kNoFrame, {}, why};
      }
      cv_.wait_for(lock, std::chrono::milliseconds(5));
    }
  }

  void Send(const Twist2& command, const robot::Observation& obs, const robot::Decision& d) {
    PublishTwist(command);
    latencies_.push_back(SteadyNs() - received_steady_ns_);
    std_msgs::String status;
    status.data = robot::StatusJson(method_.c_str(), frames_++, obs, d).dump();
    status_pub_.publish(status);
    if (debug_pub_ && debug_pub_.getNumSubscribers() > 0) {
      const cv::Mat bgr = robot::DebugImage(obs, d);
      sensor_msgs::Image msg;
      msg.header.stamp.fromNSec(static_cast<std::uint64_t>(std::max<Timestamp>(obs.t_ns, 0)));
      msg.header.frame_id = "camera";
      msg.width = static_cast<std::uint32_t>(bgr.cols);
      msg.height = static_cast<std::uint32_t>(bgr.rows);
      msg.encoding = "bgr8";
      msg.step = static_cast<std::uint32_t>(bgr.cols * 3);
      msg.data.assign(bgr.data, bgr.data + bgr.total() * 3);
      debug_pub_.publish(msg);
    }
  }

  void Stop(const std::string& reason) {
    PublishTwist(Twist2{});
    std_msgs::String status;
    status.data = robot::StopJson(method_.c_str(), ToNs(ros::Time::now()), reason).dump();
    status_pub_.publish(status);
  }

  std::vector<std::int64_t> latencies_;

 private:
  std::string estop_topic() const { return robot_.Resolve(robot_.topics.estop); }

  void PublishTwist(const Twist2& c) {
    commanded_ = true;
    geometry_msgs::Twist t;
    t.linear.x = c.v_mps;
    t.angular.z = c.omega_radps;
    cmd_pub_.publish(t);
  }

  void Warn(const std::string& kind, const std::string& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    bad_input_ = message;
    if (!warned_.insert(kind).second) return;
    if (warn_) warn_(message + " (said once)");
  }

  void Deliver(const cv::Mat& grey, const ros::Time& stamp, std::int64_t received_ns) {
    cv::Mat frame = robot::PrepareFrame(grey, robot_.mount, size_);
    std::lock_guard<std::mutex> lock(mutex_);
    frame_ = frame;
    frame_t_ns_ = stamp.isZero() ? ToNs(ros::Time::now()) : ToNs(stamp);
    frame_received_ns_ = received_ns;
    have_frame_ = true;
    bad_input_.clear();
    cv_.notify_all();
  }

  void OnImage(const sensor_msgs::ImageConstPtr& msg) {
    const std::int64_t received = SteadyNs();
    try {
      const cv::Mat grey = robot::GreyFromRaw(
          msg->encoding, msg->width, msg->height, msg->step, msg->is_bigendian != 0,
          std::string_view(reinterpret_cast<const char*>(msg->data.data()), msg->data.size()));
      Deliver(grey, msg->header.stamp, received);
    } catch (const InputError& e) {
      Warn("image:" + msg->encoding, camera_topic_ + ": " + e.what());
    }
  }

  void OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg) {
    const std::int64_t received = SteadyNs();
    try {
      const cv::Mat grey = robot::GreyFromCompressed(
          msg->format,
          std::string_view(reinterpret_cast<const char*>(msg->data.data()), msg->data.size()));
      Deliver(grey, msg->header.stamp, received);
    } catch (const InputError& e) {
      Warn("compressed:" + msg->format, camera_topic_ + ": " + e.what());
    }
  }

  void OnOdometry(const nav_msgs::OdometryConstPtr& msg) {
    const auto& p = msg->pose.pose;
    if (!std::isfinite(p.position.x) || !std::isfinite(p.position.y) ||
        !std::isfinite(Yaw(p.orientation))) {
      Warn("odometry", robot_.Resolve(robot_.topics.odometry) + ": odometry that is not finite");
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    odometry_.push_back(
        {ToNs(msg->header.stamp), Pose2{p.position.x, p.position.y, Yaw(p.orientation)}});
    while (odometry_.size() > 200) odometry_.pop_front();
    cv_.notify_all();
  }

  void OnEStop(const std_msgs::BoolConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    estop_ = msg->data;
    cv_.notify_all();
  }

  // The odometry at a frame's time: the message nearest to it. Under use_sim_time (a lockstep
  // simulator publishes the odometry of each frame's time with it) it first waits briefly (wall
  // time) for one stamped at or after the frame, so that the two pair up whichever arrives first;
  // in real time it takes the nearest it has, adding no latency.
  std::optional<Pose2> OdometryAt(Timestamp t_ns) {
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

  robot::RobotFile robot_;
  cv::Size size_;
  std::string method_;
  Logger warn_;
  ros::AsyncSpinner spinner_;
  ros::Subscriber image_sub_, odom_sub_, estop_sub_;
  ros::Publisher cmd_pub_, status_pub_, debug_pub_;
  std::string camera_topic_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool have_frame_ = false;
  bool got_frame_ = false;
  cv::Mat frame_;
  Timestamp frame_t_ns_ = 0;
  std::int64_t frame_received_ns_ = 0;
  std::int64_t received_steady_ns_ = 0;
  std::deque<std::pair<Timestamp, Pose2>> odometry_;
  bool estop_ = false;
  std::string bad_input_;
  std::set<std::string> warned_;
  Timestamp last_event_ns_ = 0;
  std::int64_t last_frame_steady_ns_ = SteadyNs();  // the last frame, or the start
  int frames_ = 0;
  bool commanded_ = false;
};

Ros1Link::Ros1Link(const robot::RobotFile& robot, cv::Size image_size, std::string method,
                   Logger warn)
    : impl_(std::make_unique<Impl>(robot, image_size, std::move(method), std::move(warn))) {}
Ros1Link::~Ros1Link() = default;
void Ros1Link::Start() { impl_->Start(); }
robot::LinkEvent Ros1Link::Next() { return impl_->Next(); }
void Ros1Link::Send(const Twist2& c, const robot::Observation& o, const robot::Decision& d) {
  impl_->Send(c, o, d);
}
void Ros1Link::Stop(const std::string& reason) { impl_->Stop(reason); }
Timestamp Ros1Link::now_ns() const { return ToNs(ros::Time::now()); }
const std::vector<std::int64_t>& Ros1Link::latencies_ns() const { return impl_->latencies_; }

}  // namespace mapless::ros1

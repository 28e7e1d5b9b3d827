#include "mapless/ros1/ros1_link.h"

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/console.h>
#include <ros/console_backend.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Bool.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/core/interrupt.h"
#include "mapless/robot/camera_image.h"
#include "mapless/robot/inbox.h"
#include "mapless/robot/status.h"

namespace mapless::ros1 {

namespace {

using SteadyClock = std::chrono::steady_clock;

Timestamp ToNs(const ros::Time& t) { return static_cast<Timestamp>(t.toNSec()); }

double Yaw(const geometry_msgs::Quaternion& q) { return YawFromQuaternion(q.x, q.y, q.z, q.w); }

// roscpp's own log lines (rosconsole) are not printed: they came colour-coded between mapless's
// lines (two nodes of one name: "Shutdown request received. Reason: [...]"). Its warnings and
// errors are kept, the last one given as the reason when the middleware shuts down, and each
// handed once to the link's logger.
std::mutex g_console_mutex;
std::string g_console_last;  // the last warning or error
Logger g_console_logger;
std::set<std::string> g_console_said;

void CapturePrint(void*, ros::console::Level level, const char* text, const char*, const char*,
                  int) {
  if (level < ros::console::levels::Warn || text == nullptr) return;
  std::string line(text);
  while (!line.empty() && (line.back() == '\n' || line.back() == ' ')) line.pop_back();
  Logger logger;
  {
    std::lock_guard<std::mutex> lock(g_console_mutex);
    g_console_last = line;
    if (!g_console_said.insert(line).second) return;
    logger = g_console_logger;
  }
  if (logger) logger("ROS 1: " + line);
}

std::string ShutdownReason() {
  std::lock_guard<std::mutex> lock(g_console_mutex);
  return g_console_last.empty() ? "the middleware shut down"
                                : "the middleware shut down: " + g_console_last;
}

}  // namespace

void StartNode(const robot::RobotFile& robot, const std::string& node_name) {
  if (ros::isInitialized()) return;
  std::map<std::string, std::string> remappings;
  if (!robot.ns.empty()) remappings["__ns"] = robot.ns;
  ros::init(remappings, node_name, ros::init_options::NoSigintHandler);
  ros::console::initialize();
  ros::console::backend::function_print = CapturePrint;
  const auto deadline = SteadyClock::now() + std::chrono::duration<double>(robot.connect_timeout_s);
  while (!ros::master::check()) {
    if (InterruptRequested())
      throw std::runtime_error("interrupted while waiting for the ROS master");
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
        method_(std::move(method)),
        inbox_(robot, size, CameraTopic(robot), warn,
               {[] { return ToNs(ros::Time::now()); }, [] { return ros::ok(); },
                [this] { return image_sub_.getNumPublishers() > 0; }, ShutdownReason}),
        spinner_(1) {
    {
      std::lock_guard<std::mutex> lock(g_console_mutex);
      g_console_logger = warn;
    }
    ros::NodeHandle nh;
    camera_topic_ = CameraTopic(robot);
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    if (robot.topics.compressed_image.empty()) {
      image_sub_ = nh.subscribe(camera_topic_, 2, &Impl::OnImage, this, hints);
    } else {
      image_sub_ = nh.subscribe(camera_topic_, 2, &Impl::OnCompressed, this, hints);
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
    inbox_.Start();
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

  robot::LinkEvent Next() { return inbox_.Next(); }

  void Send(const Twist2& command, const robot::Observation& obs, const robot::Decision& d) {
    PublishTwist(command);
    latencies_.push_back(robot::SteadyNs() - inbox_.received_steady_ns());
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
  static std::string CameraTopic(const robot::RobotFile& robot) {
    return robot.topics.compressed_image.empty() ? robot.Resolve(robot.topics.image)
                                                 : robot.Resolve(robot.topics.compressed_image);
  }

  void PublishTwist(const Twist2& c) {
    commanded_ = true;
    geometry_msgs::Twist t;
    t.linear.x = c.v_mps;
    t.angular.z = c.omega_radps;
    cmd_pub_.publish(t);
  }

  void OnImage(const sensor_msgs::ImageConstPtr& msg) {
    const std::int64_t received = robot::SteadyNs();
    try {
      const cv::Mat grey = robot::GreyFromRaw(
          msg->encoding, msg->width, msg->height, msg->step, msg->is_bigendian != 0,
          std::string_view(reinterpret_cast<const char*>(msg->data.data()), msg->data.size()));
      inbox_.Deliver(grey, ToNs(msg->header.stamp), received);
    } catch (const InputError& e) {
      inbox_.Warn("image:" + msg->encoding, camera_topic_ + ": " + e.what());
    }
  }

  void OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg) {
    const std::int64_t received = robot::SteadyNs();
    try {
      const cv::Mat grey = robot::GreyFromCompressed(
          msg->format,
          std::string_view(reinterpret_cast<const char*>(msg->data.data()), msg->data.size()));
      inbox_.Deliver(grey, ToNs(msg->header.stamp), received);
    } catch (const InputError& e) {
      inbox_.Warn("compressed:" + msg->format, camera_topic_ + ": " + e.what());
    }
  }

  void OnOdometry(const nav_msgs::OdometryConstPtr& msg) {
    const auto& p = msg->pose.pose;
    const double yaw = Yaw(p.orientation);
    if (!std::isfinite(p.position.x) || !std::isfinite(p.position.y) || !std::isfinite(yaw)) {
      inbox_.Warn("odometry",
                  robot_.Resolve(robot_.topics.odometry) + ": odometry that is not finite");
      return;
    }
    inbox_.AddOdometry(ToNs(msg->header.stamp), Pose2{p.position.x, p.position.y, yaw});
  }

  void OnEStop(const std_msgs::BoolConstPtr& msg) {
    inbox_.SetEStop(msg->data, robot_.Resolve(robot_.topics.estop));
  }

  robot::RobotFile robot_;
  std::string method_;
  robot::FrameInbox inbox_;
  ros::AsyncSpinner spinner_;
  ros::Subscriber image_sub_, odom_sub_, estop_sub_;
  ros::Publisher cmd_pub_, status_pub_, debug_pub_;
  std::string camera_topic_;
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

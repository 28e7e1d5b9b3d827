#include "mapless/ros1/sim_serve.h"

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "mapless/robot/sim_link.h"

namespace mapless::ros1 {

namespace {

ros::Time Stamp(Timestamp t_ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(std::max<Timestamp>(t_ns, 0)));
  return t;
}

class Server {
 public:
  Server(const robot::RobotFile& file, const ServeOptions& options)
      : file_(file), options_(options), spinner_(1) {
    ros::NodeHandle nh;
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    compressed_ = options.encoding == "jpeg" || options.encoding == "png";
    if (compressed_) {
      const std::string topic = file.topics.compressed_image.empty()
                                    ? file.Resolve(file.topics.image) + "/compressed"
                                    : file.Resolve(file.topics.compressed_image);
      image_pub_ = nh.advertise<sensor_msgs::CompressedImage>(topic, 2);
    } else {
      image_pub_ = nh.advertise<sensor_msgs::Image>(file.Resolve(file.topics.image), 2);
    }
    if (!file.topics.odometry.empty())
      odom_pub_ = nh.advertise<nav_msgs::Odometry>(file.Resolve(file.topics.odometry), 10);
    if (file.use_sim_time) clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    cmd_sub_ = nh.subscribe(file.Resolve(file.topics.cmd_vel), 20, &Server::OnCommand, this, hints);
    status_sub_ =
        nh.subscribe(file.Resolve(file.topics.status), 50, &Server::OnStatus, this, hints);
  }
  void Start() { spinner_.start(); }
  ~Server() { spinner_.stop(); }

  void Log(const std::string& m) const {
    if (options_.log) options_.log(m);
  }
  bool Interrupted() const { return options_.interrupted && options_.interrupted(); }

  // Lockstep: a method is connected when it subscribes the camera (and the odometry and clock we
  // publish) and publishes commands and status.
  bool MethodConnected() const {
    return image_pub_.getNumSubscribers() > 0 &&
           (!odom_pub_ || odom_pub_.getNumSubscribers() > 0) &&
           (!clock_pub_ || clock_pub_.getNumSubscribers() > 0) && cmd_sub_.getNumPublishers() > 0 &&
           status_sub_.getNumPublishers() > 0;
  }

  // Stamped with the simulated time in lockstep (it is the ROS clock there, via /clock), with
  // the ROS clock itself in real time.
  void Publish(const sim::Simulation& sim, int robot, const cv::Mat& image) {
    const ros::Time stamp = file_.use_sim_time ? Stamp(sim.now_ns()) : ros::Time::now();
    if (clock_pub_) {
      rosgraph_msgs::Clock clock;
      clock.clock = stamp;
      clock_pub_.publish(clock);
    }
    if (odom_pub_) {
      const Pose2 o = sim.robot(robot).odometry();
      nav_msgs::Odometry odom;
      odom.header.stamp = stamp;
      odom.header.frame_id = "odom";
      odom.child_frame_id = "base_link";
      odom.pose.pose.position.x = o.x_m;
      odom.pose.pose.position.y = o.y_m;
      odom.pose.pose.orientation.z = std::sin(o.theta_rad / 2.0);
      odom.pose.pose.orientation.w = std::cos(o.theta_rad / 2.0);
      odom_pub_.publish(odom);
    }
    cv::Mat frame = image;
    if (options_.size.area() > 0 && options_.size != image.size())
      cv::resize(image, frame, options_.size, 0, 0, cv::INTER_LINEAR);
    const std::string& enc = options_.encoding;
    if (compressed_) {
      sensor_msgs::CompressedImage msg;
      msg.header.stamp = stamp;
      msg.header.frame_id = "camera";
      msg.format = enc;
      std::vector<uchar> bytes;
      cv::imencode(enc == "png" ? ".png" : ".jpg", frame, bytes);
      msg.data.assign(bytes.begin(), bytes.end());
      image_pub_.publish(msg);
      return;
    }
    cv::Mat packed;
    if (enc == "rgb8") {
      cv::cvtColor(frame, packed, cv::COLOR_GRAY2RGB);
    } else if (enc == "bgr8") {
      cv::cvtColor(frame, packed, cv::COLOR_GRAY2BGR);
    } else if (enc == "mono8") {
      packed = frame.isContinuous() ? frame : frame.clone();
    } else {
      packed = cv::Mat(frame.rows, frame.cols, CV_8UC2, cv::Scalar(128, 128));  // unknown
    }
    sensor_msgs::Image msg;
    msg.header.stamp = stamp;
    msg.header.frame_id = "camera";
    msg.width = static_cast<std::uint32_t>(packed.cols);
    msg.height = static_cast<std::uint32_t>(packed.rows);
    msg.encoding = enc;
    msg.step = static_cast<std::uint32_t>(packed.cols * packed.channels());
    msg.data.assign(packed.data, packed.data + packed.total() * packed.elemSize());
    image_pub_.publish(msg);
  }

  // Waits for the next command (lockstep); false when the method left or we were interrupted.
  bool WaitCommand(int seen, Twist2* command) {
    std::unique_lock<std::mutex> lock(mutex_);
    while (commands_ <= seen) {
      if (Interrupted() || !ros::ok()) return false;
      if (cmd_sub_.getNumPublishers() == 0) return false;
      cv_.wait_for(lock, std::chrono::milliseconds(5));
    }
    *command = last_;
    return true;
  }

  int commands() {
    std::lock_guard<std::mutex> lock(mutex_);
    return commands_;
  }
  Twist2 Latest(double* age_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    *age_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_at_).count();
    return last_;
  }
  // The frame time of the method's last decision (-1: none yet).
  Timestamp DecidedAt() {
    std::lock_guard<std::mutex> lock(mutex_);
    return decided_ns_;
  }

 private:
  void OnCommand(const geometry_msgs::TwistConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    Twist2 t{msg->linear.x, msg->angular.z};
    if (!std::isfinite(t.v_mps) || !std::isfinite(t.omega_radps)) t = Twist2{};
    last_ = t;
    last_at_ = std::chrono::steady_clock::now();
    ++commands_;
    cv_.notify_all();
  }
  void OnStatus(const std_msgs::StringConstPtr& msg) {
    const nlohmann::json j = nlohmann::json::parse(msg->data, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("frame") || !j.contains("t_s") ||
        !j["t_s"].is_number())
      return;
    std::lock_guard<std::mutex> lock(mutex_);
    decided_ns_ = FromSeconds(j["t_s"].get<double>());
  }

  robot::RobotFile file_;
  ServeOptions options_;
  bool compressed_ = false;
  ros::AsyncSpinner spinner_;
  ros::Publisher image_pub_, odom_pub_, clock_pub_;
  ros::Subscriber cmd_sub_, status_sub_;
  std::mutex mutex_;
  std::condition_variable cv_;
  Twist2 last_;
  std::chrono::steady_clock::time_point last_at_ = std::chrono::steady_clock::now();
  int commands_ = 0;
  Timestamp decided_ns_ = -1;
};

}  // namespace

ServeSummary ServeSimulation(sim::Simulation& sim, int robot, const robot::RobotFile& file,
                             const ServeOptions& options) {
  Server server(file, options);
  server.Start();
  ServeSummary summary;
  std::map<Timestamp, Pose2> truth_at;
  auto finish = [&](const std::string& why) {
    summary.end = why;
    summary.sim_time_s = ToSeconds(sim.now_ns());
    summary.final_pose = sim.robot(robot).pose();
    summary.collided = sim.collided(robot);
    const Timestamp decided = server.DecidedAt();
    if (auto it = truth_at.find(decided); it != truth_at.end()) {
      summary.have_decided_pose = true;
      summary.decided_pose = it->second;
    }
    return summary;
  };

  if (file.use_sim_time) {
    server.Log("sim serve: lockstep in simulated time; waiting for a method to connect");
    while (!server.MethodConnected()) {
      if (server.Interrupted() || !ros::ok())
        return finish("interrupted before a method connected");
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    server.Log("sim serve: a method connected");
    while (true) {
      const Pose2 truth = sim.robot(robot).pose();
      truth_at[sim.now_ns()] = truth;
      summary.path.push_back(truth);
      server.Publish(sim, robot, sim.Render(robot));
      ++summary.frames;
      Twist2 command;
      if (!server.WaitCommand(summary.commands, &command))
        return finish(server.Interrupted() ? "interrupted" : "the method left");
      ++summary.commands;
      sim.SetCommand(robot, command);
      sim.Advance(options.period_s);
      if (sim.collided(robot) && summary.collision.empty()) {
        summary.collision = robot::SimulationStop(sim, robot, 1e18);
        server.Log("sim serve: " + summary.collision);
      }
      if (ToSeconds(sim.now_ns()) > options.timeout_s) return finish("timeout");
    }
  }

  server.Log("sim serve: real time at " + std::to_string(1.0 / options.period_s).substr(0, 5) +
             " Hz");
  auto next = std::chrono::steady_clock::now();
  while (true) {
    if (server.Interrupted() || !ros::ok()) return finish("interrupted");
    const Pose2 truth = sim.robot(robot).pose();
    truth_at[sim.now_ns()] = truth;
    summary.path.push_back(truth);
    server.Publish(sim, robot, sim.Render(robot));
    ++summary.frames;
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(options.period_s));
    std::this_thread::sleep_until(next);
    double age = 0.0;
    const Twist2 command = server.Latest(&age);
    sim.SetCommand(robot, age <= options.command_timeout_s ? command : Twist2{});
    summary.commands = server.commands();
    sim.Advance(options.period_s);
    if (sim.collided(robot) && summary.collision.empty()) {
      summary.collision = robot::SimulationStop(sim, robot, 1e18);
      server.Log("sim serve: " + summary.collision);
    }
    if (ToSeconds(sim.now_ns()) > options.timeout_s) return finish("timeout");
  }
}

}  // namespace mapless::ros1

#include "mapless/ros1/sim_serve.h"

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <cmath>

namespace mapless::ros1 {

namespace {

ros::Time Stamp(Timestamp t_ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(std::max<Timestamp>(t_ns, 0)));
  return t;
}

class Transport : public robot::SimTransport {
 public:
  Transport(const robot::RobotFile& file, const std::string& encoding) : spinner_(1) {
    ros::NodeHandle nh;
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    const std::string camera = robot::ServedCameraTopic(file, encoding);
    if (encoding == "jpeg" || encoding == "png") {
      image_pub_ = nh.advertise<sensor_msgs::CompressedImage>(camera, 2);
    } else {
      image_pub_ = nh.advertise<sensor_msgs::Image>(camera, 2);
    }
    if (!file.topics.odometry.empty())
      odom_pub_ = nh.advertise<nav_msgs::Odometry>(file.Resolve(file.topics.odometry), 10);
    if (file.use_sim_time) clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    cmd_sub_ =
        nh.subscribe(file.Resolve(file.topics.cmd_vel), 20, &Transport::OnTwist, this, hints);
    status_sub_ =
        nh.subscribe(file.Resolve(file.topics.status), 50, &Transport::OnString, this, hints);
    spinner_.start();
  }
  ~Transport() override { spinner_.stop(); }

  bool MethodConnected() override {
    return image_pub_.getNumSubscribers() > 0 &&
           (!odom_pub_ || odom_pub_.getNumSubscribers() > 0) &&
           (!clock_pub_ || clock_pub_.getNumSubscribers() > 0) && cmd_sub_.getNumPublishers() > 0 &&
           status_sub_.getNumPublishers() > 0;
  }
  bool MethodPresent() override { return cmd_sub_.getNumPublishers() > 0; }
  bool ok() override { return ros::ok(); }
  Timestamp now_ns() override { return static_cast<Timestamp>(ros::Time::now().toNSec()); }

  void Publish(Timestamp stamp_ns, bool clock, const Pose2& o,
               const robot::CameraMessage& image) override {
    const ros::Time stamp = Stamp(stamp_ns);
    if (clock && clock_pub_) {
      rosgraph_msgs::Clock c;
      c.clock = stamp;
      clock_pub_.publish(c);
    }
    if (odom_pub_) {
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
    if (image.compressed) {
      sensor_msgs::CompressedImage msg;
      msg.header.stamp = stamp;
      msg.header.frame_id = "camera";
      msg.format = image.encoding;
      msg.data = image.data;
      image_pub_.publish(msg);
      return;
    }
    sensor_msgs::Image msg;
    msg.header.stamp = stamp;
    msg.header.frame_id = "camera";
    msg.width = image.width;
    msg.height = image.height;
    msg.encoding = image.encoding;
    msg.step = image.step;
    msg.data = image.data;
    image_pub_.publish(msg);
  }

 private:
  void OnTwist(const geometry_msgs::TwistConstPtr& msg) {
    OnCommand(Twist2{msg->linear.x, msg->angular.z});
  }
  void OnString(const std_msgs::StringConstPtr& msg) { OnStatus(msg->data); }

  ros::AsyncSpinner spinner_;
  ros::Publisher image_pub_, odom_pub_, clock_pub_;
  ros::Subscriber cmd_sub_, status_sub_;
};

}  // namespace

robot::ServeSummary ServeSimulation(sim::Simulation& sim, int robot, const robot::RobotFile& file,
                                    const robot::ServeOptions& options) {
  Transport transport(file, options.encoding);
  return robot::ServeSimulation(sim, robot, file, options, transport);
}

}  // namespace mapless::ros1

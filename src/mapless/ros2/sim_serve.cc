#include "mapless/ros2/sim_serve.h"

#include <chrono>

#include "mapless/ros2/dds.h"
#include "mapless/ros2/messages.h"

namespace mapless::ros2 {

namespace {

class Transport : public robot::SimTransport {
 public:
  Transport(const robot::RobotFile& file, const std::string& encoding) {
    const std::string camera = robot::ServedCameraTopic(file, encoding);
    if (encoding == "jpeg" || encoding == "png") {
      image_ = MakeWriter(&sensor_msgs_msg_dds__CompressedImage__desc, camera,
                          "sensor_msgs/msg/CompressedImage", Qos::kSensorData);
    } else {
      image_ = MakeWriter(&sensor_msgs_msg_dds__Image__desc, camera, "sensor_msgs/msg/Image",
                          Qos::kSensorData);
    }
    // A robot base publishes its odometry with the default (reliable) profile.
    if (!file.topics.odometry.empty())
      odometry_ = MakeWriter(&nav_msgs_msg_dds__Odometry__desc, file.Resolve(file.topics.odometry),
                             "nav_msgs/msg/Odometry", Qos::kDefault);
    if (file.use_sim_time)
      clock_ = MakeWriter(&rosgraph_msgs_msg_dds__Clock__desc, "/clock", "rosgraph_msgs/msg/Clock",
                          Qos::kClock);
    listener_ = dds_create_listener(this);
    dds_lset_data_available(listener_, &Transport::OnTwist);
    cmd_ = MakeReader(&geometry_msgs_msg_dds__Twist__desc, file.Resolve(file.topics.cmd_vel),
                      "geometry_msgs/msg/Twist", Qos::kDefault, listener_);
    dds_lset_data_available(listener_, &Transport::OnString);
    status_ = MakeReader(&std_msgs_msg_dds__String__desc, file.Resolve(file.topics.status),
                         "std_msgs/msg/String", Qos::kDefault, listener_);
  }
  ~Transport() override {
    for (dds_entity_t e : {cmd_, status_, image_, odometry_, clock_}) Delete(e);
    dds_delete_listener(listener_);
  }

  bool MethodConnected() override {
    return MatchedReaders(image_) > 0 && (odometry_ == 0 || MatchedReaders(odometry_) > 0) &&
           (clock_ == 0 || MatchedReaders(clock_) > 0) && MatchedWriters(cmd_) > 0 &&
           MatchedWriters(status_) > 0;
  }
  bool MethodPresent() override { return MatchedWriters(cmd_) > 0; }
  bool ok() override { return true; }
  Timestamp now_ns() override {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  }

  void Publish(Timestamp stamp, bool clock, const Pose2& odometry,
               const robot::CameraMessage& image) override {
    if (clock && clock_ > 0) WriteClock(clock_, stamp);
    if (odometry_ > 0) WriteOdometry(odometry_, stamp, odometry);
    WriteImage(image_, stamp, "camera", image);
  }

 private:
  static void OnTwist(dds_entity_t reader, void* arg) {
    auto* self = static_cast<Transport*>(arg);
    TakeAll<geometry_msgs_msg_dds__Twist_>(reader, [&](const geometry_msgs_msg_dds__Twist_& t) {
      self->OnCommand(Twist2{t.linear.x, t.angular.z});
    });
  }
  static void OnString(dds_entity_t reader, void* arg) {
    auto* self = static_cast<Transport*>(arg);
    TakeAll<std_msgs_msg_dds__String_>(
        reader, [&](const std_msgs_msg_dds__String_& s) { self->OnStatus(s.data ? s.data : ""); });
  }

  dds_entity_t image_ = 0, odometry_ = 0, clock_ = 0, cmd_ = 0, status_ = 0;
  dds_listener_t* listener_ = nullptr;
};

}  // namespace

robot::ServeSummary ServeSimulation(sim::Simulation& sim, int robot, const robot::RobotFile& file,
                                    const robot::ServeOptions& options) {
  Transport transport(file, options.encoding);
  return robot::ServeSimulation(sim, robot, file, options, transport);
}

}  // namespace mapless::ros2

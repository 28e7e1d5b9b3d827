#include "mapless/ros2/ros2_link.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "mapless/core/check.h"
#include "mapless/robot/camera_image.h"
#include "mapless/robot/status.h"
#include "mapless/ros2/dds.h"
#include "mapless/ros2/messages.h"

namespace mapless::ros2 {

namespace {

Timestamp SystemNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string_view Bytes(const dds_sequence_octet& seq) {
  return {reinterpret_cast<const char*>(seq._buffer), seq._length};
}

std::string Str(const char* s) { return s ? s : ""; }

}  // namespace

class Ros2Link::Impl {
 public:
  Impl(const robot::RobotFile& robot, cv::Size size, std::string method, robot::Logger warn)
      : robot_(robot),
        method_(std::move(method)),
        camera_topic_(CameraTopic(robot)),
        inbox_(robot, size, camera_topic_, std::move(warn),
               {[this] { return Now(); }, {}, [this] { return MatchedWriters(camera_) > 0; }}) {
    // Each reader gets its own copy of the listener, with the callback set just before it.
    listener_ = dds_create_listener(this);
    if (robot.topics.compressed_image.empty()) {
      dds_lset_data_available(listener_, &Impl::OnImage);
      camera_ = MakeReader(&sensor_msgs_msg_dds__Image__desc, camera_topic_,
                           "sensor_msgs/msg/Image", Qos::kSensorData, listener_);
    } else {
      dds_lset_data_available(listener_, &Impl::OnCompressed);
      camera_ = MakeReader(&sensor_msgs_msg_dds__CompressedImage__desc, camera_topic_,
                           "sensor_msgs/msg/CompressedImage", Qos::kSensorData, listener_);
    }
    if (!robot.topics.odometry.empty()) {
      dds_lset_data_available(listener_, &Impl::OnOdometry);
      odometry_ =
          MakeReader(&nav_msgs_msg_dds__Odometry__desc, robot.Resolve(robot.topics.odometry),
                     "nav_msgs/msg/Odometry", Qos::kSensorData, listener_);
    }
    if (!robot.topics.estop.empty()) {
      dds_lset_data_available(listener_, &Impl::OnEStop);
      estop_ = MakeReader(&std_msgs_msg_dds__Bool__desc, robot.Resolve(robot.topics.estop),
                          "std_msgs/msg/Bool", Qos::kDefault, listener_);
    }
    if (robot.use_sim_time) {
      dds_lset_data_available(listener_, &Impl::OnClock);
      clock_ = MakeReader(&rosgraph_msgs_msg_dds__Clock__desc, "/clock", "rosgraph_msgs/msg/Clock",
                          Qos::kClock, listener_);
    }
    cmd_ = MakeWriter(&geometry_msgs_msg_dds__Twist__desc, robot.Resolve(robot.topics.cmd_vel),
                      "geometry_msgs/msg/Twist", Qos::kDefault);
    status_ = MakeWriter(&std_msgs_msg_dds__String__desc, robot.Resolve(robot.topics.status),
                         "std_msgs/msg/String", Qos::kDefault);
    if (!robot.topics.debug_image.empty())
      debug_ =
          MakeWriter(&sensor_msgs_msg_dds__Image__desc, robot.Resolve(robot.topics.debug_image),
                     "sensor_msgs/msg/Image", Qos::kSensorData);
  }

  ~Impl() {
    // A link that ever commanded the robot leaves it at zero velocity (and waits until the
    // zero reached the base's reader); one that only listened (teaching) publishes nothing.
    if (commanded_) {
      WriteTwist(cmd_, Twist2{});
      dds_wait_for_acks(cmd_, DDS_MSECS(500));
    }
    started_ = false;
    for (dds_entity_t e : {camera_, odometry_, estop_, clock_, cmd_, status_, debug_}) Delete(e);
    dds_delete_listener(listener_);
  }

  void Start() {
    inbox_.Start();
    started_ = true;  // frames that came before are dropped by the listener
  }

  robot::LinkEvent Next() { return inbox_.Next(); }

  void Send(const Twist2& command, const robot::Observation& obs, const robot::Decision& d) {
    PublishTwist(command);
    latencies_.push_back(robot::SteadyNs() - inbox_.received_steady_ns());
    WriteString(status_, robot::StatusJson(method_.c_str(), frames_++, obs, d).dump());
    if (debug_ > 0 && MatchedReaders(debug_) > 0) {
      const cv::Mat bgr = robot::DebugImage(obs, d);
      robot::CameraMessage msg;
      msg.encoding = "bgr8";
      msg.width = static_cast<std::uint32_t>(bgr.cols);
      msg.height = static_cast<std::uint32_t>(bgr.rows);
      msg.step = static_cast<std::uint32_t>(bgr.cols * 3);
      msg.data.assign(bgr.data, bgr.data + bgr.total() * 3);
      WriteImage(debug_, obs.t_ns, "camera", msg);
    }
  }

  void Stop(const std::string& reason) {
    PublishTwist(Twist2{});
    WriteString(status_, robot::StopJson(method_.c_str(), Now(), reason).dump());
  }

  Timestamp Now() const { return robot_.use_sim_time ? sim_now_.load() : SystemNs(); }

  std::vector<std::int64_t> latencies_;

 private:
  static std::string CameraTopic(const robot::RobotFile& robot) {
    return robot.topics.compressed_image.empty() ? robot.Resolve(robot.topics.image)
                                                 : robot.Resolve(robot.topics.compressed_image);
  }
  static Impl* Self(void* arg) { return static_cast<Impl*>(arg); }

  void PublishTwist(const Twist2& c) {
    commanded_ = true;
    WriteTwist(cmd_, c);
  }

  // The listener callbacks run on Cyclone's receive threads; the newest frame wins. Frames before
  // Start() are dropped.
  static void OnImage(dds_entity_t reader, void* arg) {
    Impl* self = Self(arg);
    const std::int64_t received = robot::SteadyNs();
    TakeAll<sensor_msgs_msg_dds__Image_>(reader, [&](const sensor_msgs_msg_dds__Image_& m) {
      if (!self->started_) return;
      const std::string encoding = Str(m.encoding);
      try {
        const cv::Mat grey = robot::GreyFromRaw(encoding, m.width, m.height, m.step,
                                                m.is_bigendian != 0, Bytes(m.data));
        self->inbox_.Deliver(grey, FromTime(m.header.stamp), received);
      } catch (const InputError& e) {
        self->inbox_.Warn("image:" + encoding, self->camera_topic_ + ": " + e.what());
      }
    });
  }

  static void OnCompressed(dds_entity_t reader, void* arg) {
    Impl* self = Self(arg);
    const std::int64_t received = robot::SteadyNs();
    TakeAll<sensor_msgs_msg_dds__CompressedImage_>(
        reader, [&](const sensor_msgs_msg_dds__CompressedImage_& m) {
          if (!self->started_) return;
          const std::string format = Str(m.format);
          try {
            const cv::Mat grey = robot::GreyFromCompressed(format, Bytes(m.data));
            self->inbox_.Deliver(grey, FromTime(m.header.stamp), received);
          } catch (const InputError& e) {
            self->inbox_.Warn("compressed:" + format, self->camera_topic_ + ": " + e.what());
          }
        });
  }

  static void OnOdometry(dds_entity_t reader, void* arg) {
    Impl* self = Self(arg);
    TakeAll<nav_msgs_msg_dds__Odometry_>(reader, [&](const nav_msgs_msg_dds__Odometry_& m) {
      const auto& p = m.pose.pose;
      const double yaw =
          YawFromQuaternion(p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w);
      if (!std::isfinite(p.position.x) || !std::isfinite(p.position.y) || !std::isfinite(yaw)) {
        self->inbox_.Warn("odometry", self->robot_.Resolve(self->robot_.topics.odometry) +
                                          ": odometry that is not finite");
        return;
      }
      self->inbox_.AddOdometry(FromTime(m.header.stamp), Pose2{p.position.x, p.position.y, yaw});
    });
  }

  static void OnEStop(dds_entity_t reader, void* arg) {
    Impl* self = Self(arg);
    TakeAll<std_msgs_msg_dds__Bool_>(reader, [&](const std_msgs_msg_dds__Bool_& m) {
      self->inbox_.SetEStop(m.data, self->robot_.Resolve(self->robot_.topics.estop));
    });
  }

  static void OnClock(dds_entity_t reader, void* arg) {
    Impl* self = Self(arg);
    TakeAll<rosgraph_msgs_msg_dds__Clock_>(reader, [&](const rosgraph_msgs_msg_dds__Clock_& m) {
      self->sim_now_ = FromTime(m.clock);
    });
  }

  robot::RobotFile robot_;
  std::string method_;
  std::string camera_topic_;
  std::atomic<Timestamp> sim_now_{0};
  std::atomic<bool> started_{false};
  // Entities before the inbox: its publisher check reads camera_.
  dds_entity_t camera_ = 0, odometry_ = 0, estop_ = 0, clock_ = 0;
  dds_entity_t cmd_ = 0, status_ = 0, debug_ = 0;
  dds_listener_t* listener_ = nullptr;
  robot::FrameInbox inbox_;
  int frames_ = 0;
  bool commanded_ = false;
};

Ros2Link::Ros2Link(const robot::RobotFile& robot, cv::Size image_size, std::string method,
                   robot::Logger warn)
    : impl_(std::make_unique<Impl>(robot, image_size, std::move(method), std::move(warn))) {}
Ros2Link::~Ros2Link() = default;
void Ros2Link::Start() { impl_->Start(); }
robot::LinkEvent Ros2Link::Next() { return impl_->Next(); }
void Ros2Link::Send(const Twist2& c, const robot::Observation& o, const robot::Decision& d) {
  impl_->Send(c, o, d);
}
void Ros2Link::Stop(const std::string& reason) { impl_->Stop(reason); }
Timestamp Ros2Link::now_ns() const { return impl_->Now(); }
const std::vector<std::int64_t>& Ros2Link::latencies_ns() const { return impl_->latencies_; }

}  // namespace mapless::ros2

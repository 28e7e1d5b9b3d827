#include "mapless/ros2/messages.h"

#include <cmath>

namespace mapless::ros2 {

namespace {

// The generated types hold `char*` and non-const buffers; dds_write only reads them.
char* Chars(const std::string& s) { return const_cast<char*>(s.c_str()); }

dds_sequence_octet Octets(const std::vector<std::uint8_t>& v) {
  dds_sequence_octet seq{};
  seq._maximum = seq._length = static_cast<std::uint32_t>(v.size());
  seq._buffer = const_cast<std::uint8_t*>(v.data());
  seq._release = false;
  return seq;
}

const std::string kOdom = "odom";
const std::string kBaseLink = "base_link";

}  // namespace

builtin_interfaces_msg_dds__Time_ ToTime(Timestamp t_ns) {
  if (t_ns < 0) t_ns = 0;
  builtin_interfaces_msg_dds__Time_ t{};
  t.sec = static_cast<std::int32_t>(t_ns / kNsPerSecond);
  t.nanosec = static_cast<std::uint32_t>(t_ns % kNsPerSecond);
  return t;
}

Timestamp FromTime(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<Timestamp>(t.sec) * kNsPerSecond + static_cast<Timestamp>(t.nanosec);
}

dds_return_t WriteTwist(dds_entity_t writer, const Twist2& c) {
  geometry_msgs_msg_dds__Twist_ t{};
  t.linear.x = c.v_mps;
  t.angular.z = c.omega_radps;
  return dds_write(writer, &t);
}

dds_return_t WriteString(dds_entity_t writer, const std::string& text) {
  std_msgs_msg_dds__String_ s{};
  s.data = Chars(text);
  return dds_write(writer, &s);
}

dds_return_t WriteBool(dds_entity_t writer, bool value) {
  std_msgs_msg_dds__Bool_ b{};
  b.data = value;
  return dds_write(writer, &b);
}

dds_return_t WriteClock(dds_entity_t writer, Timestamp t_ns) {
  rosgraph_msgs_msg_dds__Clock_ c{};
  c.clock = ToTime(t_ns);
  return dds_write(writer, &c);
}

dds_return_t WriteOdometry(dds_entity_t writer, Timestamp t_ns, const Pose2& pose) {
  nav_msgs_msg_dds__Odometry_ o{};
  o.header.stamp = ToTime(t_ns);
  o.header.frame_id = Chars(kOdom);
  o.child_frame_id = Chars(kBaseLink);
  o.pose.pose.position.x = pose.x_m;
  o.pose.pose.position.y = pose.y_m;
  o.pose.pose.orientation.z = std::sin(pose.theta_rad / 2.0);
  o.pose.pose.orientation.w = std::cos(pose.theta_rad / 2.0);
  return dds_write(writer, &o);
}

dds_return_t WriteImage(dds_entity_t writer, Timestamp t_ns, const std::string& frame_id,
                        const robot::CameraMessage& image) {
  if (image.compressed) {
    sensor_msgs_msg_dds__CompressedImage_ m{};
    m.header.stamp = ToTime(t_ns);
    m.header.frame_id = Chars(frame_id);
    m.format = Chars(image.encoding);
    m.data = Octets(image.data);
    return dds_write(writer, &m);
  }
  sensor_msgs_msg_dds__Image_ m{};
  m.header.stamp = ToTime(t_ns);
  m.header.frame_id = Chars(frame_id);
  m.height = image.height;
  m.width = image.width;
  m.encoding = Chars(image.encoding);
  m.is_bigendian = 0;
  m.step = image.step;
  m.data = Octets(image.data);
  return dds_write(writer, &m);
}

}  // namespace mapless::ros2

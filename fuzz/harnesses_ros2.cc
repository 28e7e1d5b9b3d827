// The ROS 2 harness (harnesses.h: Ros2Message), built with the ROS 2 link: the bytes as a DDS
// sample's serialized data reach Cyclone DDS's decoder for the type mapless reads on that topic,
// exactly as a sample from the network does (the encapsulation header, dds_stream_normalize,
// which validates every length against the bytes and the type, then dds_stream_read_sample), and
// a sample it accepts goes through what the robot link does with it.
#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/ddsi/ddsi_serdata_default.h>
#include <dds/ddsi/q_protocol.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "harnesses.h"
#include "mapless/core/check.h"
#include "mapless/core/pose.h"
#include "mapless/robot/camera_image.h"
#include "mapless/ros2/messages.h"

namespace mapless::fuzz {
namespace {

struct Type {
  const dds_topic_descriptor_t* desc;
  void (*use)(const void* sample);
};

std::string_view Bytes(const dds_sequence_octet& s) {
  return {reinterpret_cast<const char*>(s._buffer), s._length};
}
std::string Str(const char* s) { return s ? s : ""; }

void UseImage(const void* p) {
  const auto& m = *static_cast<const sensor_msgs_msg_dds__Image_*>(p);
  try {
    const cv::Mat grey = robot::GreyFromRaw(Str(m.encoding), m.width, m.height, m.step,
                                            m.is_bigendian != 0, Bytes(m.data));
    robot::PrepareFrame(grey, robot::CameraMount::kUpright, cv::Size(320, 240));
  } catch (const InputError&) {
  }
  (void)ros2::FromTime(m.header.stamp);
}
void UseCompressed(const void* p) {
  const auto& m = *static_cast<const sensor_msgs_msg_dds__CompressedImage_*>(p);
  try {
    robot::PrepareFrame(robot::GreyFromCompressed(Str(m.format), Bytes(m.data)),
                        robot::CameraMount::kMirrored, cv::Size(320, 240));
  } catch (const InputError&) {
  }
}
void UseOdometry(const void* p) {
  const auto& m = *static_cast<const nav_msgs_msg_dds__Odometry_*>(p);
  const auto& q = m.pose.pose.orientation;
  const double yaw = YawFromQuaternion(q.x, q.y, q.z, q.w);
  volatile bool finite = std::isfinite(yaw) && std::isfinite(m.pose.pose.position.x);
  (void)finite;
  (void)ros2::FromTime(m.header.stamp);
}
void UseBool(const void* p) { (void)static_cast<const std_msgs_msg_dds__Bool_*>(p)->data; }
void UseClock(const void* p) {
  (void)ros2::FromTime(static_cast<const rosgraph_msgs_msg_dds__Clock_*>(p)->clock);
}
void UseTwist(const void* p) {
  const auto& t = *static_cast<const geometry_msgs_msg_dds__Twist_*>(p);
  volatile double v = t.linear.x + t.angular.z;
  (void)v;
}
void UseString(const void* p) {
  volatile std::size_t n = Str(static_cast<const std_msgs_msg_dds__String_*>(p)->data).size();
  (void)n;
}

// What mapless reads: the camera (raw or compressed), odometry, the e-stop and the clock (every
// link); sim serve reads cmd_vel and the status.
const Type kTypes[] = {{&sensor_msgs_msg_dds__Image__desc, UseImage},
                       {&sensor_msgs_msg_dds__CompressedImage__desc, UseCompressed},
                       {&nav_msgs_msg_dds__Odometry__desc, UseOdometry},
                       {&std_msgs_msg_dds__Bool__desc, UseBool},
                       {&rosgraph_msgs_msg_dds__Clock__desc, UseClock},
                       {&geometry_msgs_msg_dds__Twist__desc, UseTwist},
                       {&std_msgs_msg_dds__String__desc, UseString}};

}  // namespace

void Ros2Message(const std::string& input) {
  if (input.size() < 1 + 4) return;
  const Type& type = kTypes[static_cast<unsigned char>(input[0]) % std::size(kTypes)];
  const dds_topic_descriptor_t& d = *type.desc;
  ddsi_sertype_default sertype{};
  sertype.encoding_format = CDR_ENC_FORMAT_PLAIN;
  sertype.write_encoding_version = CDR_ENC_VERSION_1;
  sertype.type.size = d.m_size;
  sertype.type.align = d.m_align;
  sertype.type.flagset = d.m_flagset;
  sertype.type.ops.nops = d.m_nops;
  sertype.type.ops.ops = const_cast<uint32_t*>(d.m_ops);
  // The encapsulation header, as Cyclone takes it from the wire: the representation (big- or
  // little-endian plain CDR; anything else is dropped) and two bytes of options.
  std::uint16_t id = 0;  // as Cyclone reads it: the two bytes in memory order
  std::memcpy(&id, input.data() + 1, 2);
  if (id != CDR_BE && id != CDR_LE) return;
  const bool bswap = (id == CDR_LE) != (DDSRT_ENDIAN == DDSRT_LITTLE_ENDIAN);
  // Normalized in place, as Cyclone does with the received bytes: an aligned copy.
  std::vector<std::uint64_t> buffer((input.size() - 5 + 7) / 8 + 1);
  std::memcpy(buffer.data(), input.data() + 5, input.size() - 5);
  const auto size = static_cast<uint32_t>(input.size() - 5);
  uint32_t actual = 0;
  if (!dds_stream_normalize(buffer.data(), size, bswap, CDR_ENC_VERSION_1, &sertype, false,
                            &actual))
    return;  // refused: the sample is dropped, as from the network
  std::vector<std::uint64_t> sample(d.m_size / 8 + 2, 0);
  dds_istream_t is;
  dds_istream_init(&is, actual, buffer.data(), CDR_ENC_VERSION_1);
  dds_stream_read_sample(&is, sample.data(), &sertype);
  type.use(sample.data());
  dds_stream_free_sample(sample.data(), d.m_ops);
  dds_istream_fini(&is);
}

}  // namespace mapless::fuzz

// The C++ side of the ROS 2 wire-format test (tests/ros2/interop.sh, issue 18).
//   cdr_tool encode DIR   every message type mapless writes, written by mapless's own writers
//                         (ros2/messages.h) and taken off the DDS reader as raw CDR: DIR/NAME.cdr,
//                         DIR/NAME.json (the values written, as ROS field names), DIR/NAME.msg
//                         (the ROS 2 definition, concatenated) and DIR/NAME.type
//   cdr_tool decode DIR   every DIR/NAME.in.cdr (written by Foxglove's ROS 2 writer) decoded by
//                         Cyclone into mapless's types, printed as DIR/NAME.in.decoded.json
// Exit 0 when every message was captured or decoded, 1 otherwise.
#include <dds/ddsi/ddsi_serdata.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "mapless/ros2/dds.h"
#include "mapless/ros2/messages.h"
#include "mapless/ros2/type_hash.h"

namespace {

using nlohmann::json;
using namespace mapless;        // NOLINT: a test program
using namespace mapless::ros2;  // NOLINT

json Time(const builtin_interfaces_msg_dds__Time_& t) {
  return {{"sec", t.sec}, {"nanosec", t.nanosec}};
}
json Header(const std_msgs_msg_dds__Header_& h) {
  return {{"stamp", Time(h.stamp)}, {"frame_id", h.frame_id ? h.frame_id : ""}};
}
json Vec(const geometry_msgs_msg_dds__Vector3_& v) { return {{"x", v.x}, {"y", v.y}, {"z", v.z}}; }
json Twist(const geometry_msgs_msg_dds__Twist_& t) {
  return {{"linear", Vec(t.linear)}, {"angular", Vec(t.angular)}};
}
json Bytes(const dds_sequence_octet& s) {
  return json(std::vector<int>(s._buffer, s._buffer + s._length));
}
json Doubles(const double* d, int n) { return json(std::vector<double>(d, d + n)); }

struct Kind {
  std::string name;      // file name
  std::string ros_type;  // geometry_msgs/msg/Twist
  const dds_topic_descriptor_t* desc;
  Qos qos;
  std::function<dds_return_t(dds_entity_t)> write;  // mapless's writer
  std::function<json(const void*)> print;           // a decoded sample as ROS fields
};

std::vector<Kind> Kinds() {
  robot::CameraMessage mono;
  mono.encoding = "mono8";
  mono.width = 4;
  mono.height = 3;
  mono.step = 4;
  for (int i = 0; i < 12; ++i) mono.data.push_back(static_cast<std::uint8_t>(i * 21 + 3));
  robot::CameraMessage jpeg;
  jpeg.compressed = true;
  jpeg.encoding = "jpeg";
  jpeg.data = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x10, 0x4A, 0x46, 0x49, 0x46, 0xFF, 0xD9};
  const Timestamp t = 1732454400LL * kNsPerSecond + 123456789;
  return {
      {"twist", "geometry_msgs/msg/Twist", &geometry_msgs_msg_dds__Twist__desc, Qos::kDefault,
       [](dds_entity_t w) {
         return WriteTwist(w, Twist2{0.25, -0.5});
       },
       [](const void* s) { return Twist(*static_cast<const geometry_msgs_msg_dds__Twist_*>(s)); }},
      {"string", "std_msgs/msg/String", &std_msgs_msg_dds__String__desc, Qos::kDefault,
       [](dds_entity_t w) {
         return WriteString(w, R"({"method":"repeat","frame":7,"status":"driving – ok"})");
       },
       [](const void* s) {
         const auto* m = static_cast<const std_msgs_msg_dds__String_*>(s);
         return json{{"data", m->data ? m->data : ""}};
       }},
      {"bool", "std_msgs/msg/Bool", &std_msgs_msg_dds__Bool__desc, Qos::kDefault,
       [](dds_entity_t w) { return WriteBool(w, true); },
       [](const void* s) {
         return json{{"data", static_cast<const std_msgs_msg_dds__Bool_*>(s)->data}};
       }},
      {"clock", "rosgraph_msgs/msg/Clock", &rosgraph_msgs_msg_dds__Clock__desc, Qos::kClock,
       [t](dds_entity_t w) { return WriteClock(w, t); },
       [](const void* s) {
         return json{{"clock", Time(static_cast<const rosgraph_msgs_msg_dds__Clock_*>(s)->clock)}};
       }},
      {"odometry", "nav_msgs/msg/Odometry", &nav_msgs_msg_dds__Odometry__desc, Qos::kDefault,
       [t](dds_entity_t w) {
         return WriteOdometry(w, t, Pose2{1.5, -2.25, 0.75});
       },
       [](const void* s) {
         const auto* m = static_cast<const nav_msgs_msg_dds__Odometry_*>(s);
         const auto& p = m->pose.pose;
         return json{
             {"header", Header(m->header)},
             {"child_frame_id", m->child_frame_id ? m->child_frame_id : ""},
             {"pose",
              {{"pose",
                {{"position", {{"x", p.position.x}, {"y", p.position.y}, {"z", p.position.z}}},
                 {"orientation",
                  {{"x", p.orientation.x},
                   {"y", p.orientation.y},
                   {"z", p.orientation.z},
                   {"w", p.orientation.w}}}}},
               {"covariance", Doubles(m->pose.covariance, 36)}}},
             {"twist",
              {{"twist", Twist(m->twist.twist)},
               {"covariance", Doubles(m->twist.covariance, 36)}}}};
       }},
      {"image", "sensor_msgs/msg/Image", &sensor_msgs_msg_dds__Image__desc, Qos::kSensorData,
       [t, mono](dds_entity_t w) { return WriteImage(w, t, "camera", mono); },
       [](const void* s) {
         const auto* m = static_cast<const sensor_msgs_msg_dds__Image_*>(s);
         return json{{"header", Header(m->header)},
                     {"height", m->height},
                     {"width", m->width},
                     {"encoding", m->encoding ? m->encoding : ""},
                     {"is_bigendian", m->is_bigendian},
                     {"step", m->step},
                     {"data", Bytes(m->data)}};
       }},
      {"compressed_image", "sensor_msgs/msg/CompressedImage",
       &sensor_msgs_msg_dds__CompressedImage__desc, Qos::kSensorData,
       [t, jpeg](dds_entity_t w) { return WriteImage(w, t, "camera", jpeg); },
       [](const void* s) {
         const auto* m = static_cast<const sensor_msgs_msg_dds__CompressedImage_*>(s);
         return json{{"header", Header(m->header)},
                     {"format", m->format ? m->format : ""},
                     {"data", Bytes(m->data)}};
       }},
  };
}

void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

ddsrt_iovec_t Iov(const std::string& bytes) {
  ddsrt_iovec_t iov{};
  iov.iov_base = const_cast<char*>(bytes.data());
  iov.iov_len = bytes.size();
  return iov;
}

// CDR bytes decoded by Cyclone into mapless's type, written as ROS fields to `path`; false when
// Cyclone refuses them.
bool DecodeToJson(const Kind& k, const ddsi_sertype* type, const std::string& bytes,
                  const std::string& path) {
  ddsrt_iovec_t iov = Iov(bytes);
  ddsi_serdata* d = ddsi_serdata_from_ser_iov(type, SDK_DATA, 1, &iov, bytes.size());
  void* sample = dds_alloc(k.desc->m_size);
  const bool ok = d != nullptr && ddsi_serdata_to_sample(d, sample, nullptr, nullptr);
  if (ok) WriteFile(path, k.print(sample).dump(1) + "\n");
  dds_sample_free(sample, k.desc, DDS_FREE_ALL);
  if (d) ddsi_serdata_unref(d);
  return ok;
}

// Writes one sample with mapless's writer and takes it off a reader of the same topic as raw CDR.
// Also returns the sertype (for decoding).
std::string Capture(const Kind& k, const ddsi_sertype** type) {
  const std::string topic = "/mapless_interop/" + k.name;
  const dds_entity_t reader = MakeReader(k.desc, topic, k.ros_type, k.qos, nullptr);
  const dds_entity_t writer = MakeWriter(k.desc, topic, k.ros_type, k.qos);
  for (int i = 0; i < 200 && MatchedReaders(writer) == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (k.write(writer) < 0) return {};
  for (int i = 0; i < 200; ++i) {
    ddsi_serdata* data = nullptr;
    dds_sample_info_t info;
    if (dds_takecdr(reader, &data, 1, &info, DDS_ANY_STATE) == 1) {
      std::string bytes(ddsi_serdata_size(data), '\0');
      ddsi_serdata_to_ser(data, 0, bytes.size(), bytes.data());
      *type = data->type;
      ddsi_serdata_unref(data);
      return bytes;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 || (std::string(argv[1]) != "encode" && std::string(argv[1]) != "decode")) {
    std::fprintf(stderr, "usage: cdr_tool encode|decode DIR\n");
    return 2;
  }
  const std::string mode = argv[1], dir = argv[2];
  int failures = 0;
  for (const Kind& k : Kinds()) {
    const ddsi_sertype* type = nullptr;
    const std::string bytes = Capture(k, &type);
    if (bytes.empty() || type == nullptr) {
      std::printf("FAIL %s: no sample came back\n", k.name.c_str());
      ++failures;
      continue;
    }
    if (mode == "encode") {
      // What was written, read back through Cyclone's own decoder: the values as ROS fields.
      const bool ok = DecodeToJson(k, type, bytes, dir + "/" + k.name + ".json");
      WriteFile(dir + "/" + k.name + ".cdr", bytes);
      WriteFile(dir + "/" + k.name + ".msg", ConcatenatedDefinition(k.ros_type));
      WriteFile(dir + "/" + k.name + ".type", k.ros_type);
      std::printf("%s %s: %zu bytes\n", ok ? "ok  " : "FAIL", k.name.c_str(), bytes.size());
      failures += ok ? 0 : 1;
      continue;
    }
    const std::string in = dir + "/" + k.name + ".in.cdr";
    const std::string foreign = ReadFile(in);
    if (foreign.empty()) continue;  // not a type the other side encodes
    const bool ok = DecodeToJson(k, type, foreign, dir + "/" + k.name + ".in.decoded.json");
    std::printf("%s %s: %zu bytes decoded by Cyclone\n", ok ? "ok  " : "FAIL", k.name.c_str(),
                foreign.size());
    failures += ok ? 0 : 1;
  }
  std::fflush(stdout);
  std::_Exit(failures == 0 ? 0 : 1);
}

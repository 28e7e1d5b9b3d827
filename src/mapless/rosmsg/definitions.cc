#include "mapless/rosmsg/definitions.h"

#include <map>
#include <set>
#include <stdexcept>

namespace mapless::rosmsg {

namespace {

// ROS 2 common_interfaces / rcl_interfaces, field for field (identical in Humble and Jazzy).
// Nested types are written package/msg/Type here.
std::vector<MsgDefinition> Definitions() {
  const std::string kTime = "builtin_interfaces/msg/Time";
  const std::string kHeader = "std_msgs/msg/Header";
  const std::string kVector3 = "geometry_msgs/msg/Vector3";
  return {
      {kTime, {{"sec", "int32"}, {"nanosec", "uint32"}}},
      {kHeader, {{"stamp", kTime}, {"frame_id", "string"}}},
      {"std_msgs/msg/String", {{"data", "string"}}},
      {"std_msgs/msg/Bool", {{"data", "bool"}}},
      {"rosgraph_msgs/msg/Clock", {{"clock", kTime}}},
      {kVector3, {{"x", "float64"}, {"y", "float64"}, {"z", "float64"}}},
      {"geometry_msgs/msg/Twist", {{"linear", kVector3}, {"angular", kVector3}}},
      {"geometry_msgs/msg/Point", {{"x", "float64"}, {"y", "float64"}, {"z", "float64"}}},
      {"geometry_msgs/msg/Quaternion",
       {{"x", "float64"}, {"y", "float64"}, {"z", "float64"}, {"w", "float64"}}},
      {"geometry_msgs/msg/Pose",
       {{"position", "geometry_msgs/msg/Point"}, {"orientation", "geometry_msgs/msg/Quaternion"}}},
      {"geometry_msgs/msg/PoseWithCovariance",
       {{"pose", "geometry_msgs/msg/Pose"}, {"covariance", "float64[36]"}}},
      {"geometry_msgs/msg/TwistWithCovariance",
       {{"twist", "geometry_msgs/msg/Twist"}, {"covariance", "float64[36]"}}},
      {"nav_msgs/msg/Odometry",
       {{"header", kHeader},
        {"child_frame_id", "string"},
        {"pose", "geometry_msgs/msg/PoseWithCovariance"},
        {"twist", "geometry_msgs/msg/TwistWithCovariance"}}},
      {"sensor_msgs/msg/Image",
       {{"header", kHeader},
        {"height", "uint32"},
        {"width", "uint32"},
        {"encoding", "string"},
        {"is_bigendian", "uint8"},
        {"step", "uint32"},
        {"data", "uint8[]"}}},
      {"sensor_msgs/msg/CompressedImage",
       {{"header", kHeader}, {"format", "string"}, {"data", "uint8[]"}}},
      {"sensor_msgs/msg/RegionOfInterest",
       {{"x_offset", "uint32"},
        {"y_offset", "uint32"},
        {"height", "uint32"},
        {"width", "uint32"},
        {"do_rectify", "bool"}}},
      {"sensor_msgs/msg/CameraInfo",
       {{"header", kHeader},
        {"height", "uint32"},
        {"width", "uint32"},
        {"distortion_model", "string"},
        {"d", "float64[]"},
        {"k", "float64[9]"},
        {"r", "float64[9]"},
        {"p", "float64[12]"},
        {"binning_x", "uint32"},
        {"binning_y", "uint32"},
        {"roi", "sensor_msgs/msg/RegionOfInterest"}}},
      {"geometry_msgs/msg/PoseStamped", {{"header", kHeader}, {"pose", "geometry_msgs/msg/Pose"}}},
  };
}

struct FieldType {
  int type_id = 0;
  int capacity = 0;
  std::string nested;  // package/msg/Type
};

// type_description_interfaces/msg/FieldType: the primitive ids, +48 for a fixed array, +144 for
// an unbounded sequence.
FieldType ParseFieldType(const std::string& text) {
  static const std::map<std::string, int> kPrimitive = {
      {"int8", 2},   {"uint8", 3}, {"int16", 4},  {"uint16", 5},   {"int32", 6},
      {"uint32", 7}, {"int64", 8}, {"uint64", 9}, {"float32", 10}, {"float64", 11},
      {"char", 13},  {"bool", 15}, {"byte", 16},  {"string", 17},  {"wstring", 18},
  };
  FieldType t;
  std::string base = text;
  int offset = 0;
  if (const auto open = text.find('['); open != std::string::npos) {
    base = text.substr(0, open);
    const std::string inside = text.substr(open + 1, text.size() - open - 2);
    if (inside.empty()) {
      offset = 144;
    } else {
      offset = 48;
      t.capacity = std::stoi(inside);
    }
  }
  if (auto it = kPrimitive.find(base); it != kPrimitive.end()) {
    t.type_id = it->second + offset;
  } else {
    t.type_id = 1 + offset;  // NESTED_TYPE
    t.nested = base;
  }
  return t;
}

void Referenced(const std::string& type, std::set<std::string>* out) {
  for (const MsgField& f : FindMessage(type).fields) {
    const FieldType t = ParseFieldType(f.type);
    if (!t.nested.empty() && out->insert(t.nested).second) Referenced(t.nested, out);
  }
}

// JSON as Python's json.dumps(separators=(', ', ': ')) writes it (the names are plain ASCII).
std::string DescriptionJson(const MsgDefinition& d) {
  std::string s = "{\"type_name\": \"" + d.type + "\", \"fields\": [";
  for (std::size_t i = 0; i < d.fields.size(); ++i) {
    const FieldType t = ParseFieldType(d.fields[i].type);
    if (i > 0) s += ", ";
    s += "{\"name\": \"" + d.fields[i].name +
         "\", \"type\": {\"type_id\": " + std::to_string(t.type_id) +
         ", \"capacity\": " + std::to_string(t.capacity) +
         ", \"string_capacity\": 0, \"nested_type_name\": \"" + t.nested + "\"}}";
  }
  return s + "]}";
}

// "geometry_msgs/msg/Vector3" -> "geometry_msgs/Vector3" (how .msg files name other types).
std::string MsgName(const std::string& type) {
  const auto slash = type.find("/msg/");
  return slash == std::string::npos ? type : type.substr(0, slash) + "/" + type.substr(slash + 5);
}

std::string MsgText(const MsgDefinition& d) {
  std::string s;
  for (const MsgField& f : d.fields) {
    const FieldType t = ParseFieldType(f.type);
    s += (t.nested.empty() ? f.type : MsgName(f.type)) + " " + f.name + "\n";
  }
  return s;
}

}  // namespace

const std::vector<MsgDefinition>& KnownMessages() {
  static const std::vector<MsgDefinition> kDefinitions = Definitions();
  return kDefinitions;
}

const MsgDefinition& FindMessage(const std::string& type) {
  for (const MsgDefinition& d : KnownMessages())
    if (d.type == type) return d;
  throw std::out_of_range("unknown ROS 2 message type " + type);
}

std::string TypeDescriptionJson(const std::string& type) {
  std::set<std::string> referenced;  // sorted by name, as the generator sorts them
  Referenced(type, &referenced);
  std::string s = "{\"type_description\": " + DescriptionJson(FindMessage(type)) +
                  ", \"referenced_type_descriptions\": [";
  bool first = true;
  for (const std::string& r : referenced) {
    if (!first) s += ", ";
    first = false;
    s += DescriptionJson(FindMessage(r));
  }
  return s + "]}";
}

std::string ConcatenatedDefinition(const std::string& type) {
  std::set<std::string> referenced;
  Referenced(type, &referenced);
  std::string s = MsgText(FindMessage(type));
  for (const std::string& r : referenced) {
    s += "================================================================================\n";
    s += "MSG: " + MsgName(r) + "\n" + MsgText(FindMessage(r));
  }
  return s;
}

}  // namespace mapless::rosmsg

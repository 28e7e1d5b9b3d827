// The ROS message definitions mapless writes and reads (the .msg fields of common_interfaces and
// rcl_interfaces, identical in ROS 2 Humble and Jazzy), with no middleware: the ROS 2 link hashes
// them (ros2/type_hash.h), recordings carry them as MCAP schemas (recording/).
#pragma once

#include <string>
#include <vector>

namespace mapless::rosmsg {

// A field of a message: its name and its type as written in a .msg file ("float64",
// "uint8[]", "float64[36]", "string", "builtin_interfaces/Time", "geometry_msgs/Vector3").
struct MsgField {
  std::string name;
  std::string type;
};

struct MsgDefinition {
  std::string type;  // "geometry_msgs/msg/Twist"
  std::vector<MsgField> fields;
};

// The definitions of the messages mapless speaks, and those they refer to.
const std::vector<MsgDefinition>& KnownMessages();

// The definition of `type` ("geometry_msgs/msg/Twist"); throws std::out_of_range.
const MsgDefinition& FindMessage(const std::string& type);

// The type description JSON (REP-2016) that the ROS 2 type hash is taken of.
std::string TypeDescriptionJson(const std::string& type);

// The .msg text of a type followed by the types it refers to, each after a line of '=' and
// "MSG: package/Type" (the form rosbag2 and Foxglove use for ROS 2 schemas).
std::string ConcatenatedDefinition(const std::string& type);

}  // namespace mapless::rosmsg

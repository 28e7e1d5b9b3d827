// The ROS 2 type hash (REP-2016, "RIHS01"): SHA-256 of the type description of a message (its
// fields and the types they refer to) as the ROS 2 interface generator writes it in JSON. Iron and
// later (Jazzy) put it in every endpoint's USER_DATA as `typehash=RIHS01_<64 hex>;` and show it in
// `ros2 topic info -v`; matching does not depend on it (Humble has none). Computed here from the
// message definitions of the types mapless speaks (the .msg fields of common_interfaces), and
// checked by a test against the hashes ROS 2 Jazzy prints.
#pragma once

#include <string>
#include <vector>

namespace mapless::ros2 {

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

// The type description JSON that is hashed (exposed for the test).
std::string TypeDescriptionJson(const std::string& type);

// "RIHS01_<hex>" of a known message type; throws std::out_of_range for an unknown one.
std::string TypeHash(const std::string& type);

// The .msg text of a type followed by the types it refers to, each after a line of '=' and
// "MSG: package/Type" (the form rosbag2 and Foxglove use for ROS 2 schemas).
std::string ConcatenatedDefinition(const std::string& type);

}  // namespace mapless::ros2

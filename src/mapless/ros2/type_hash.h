// The ROS 2 type hash (REP-2016, "RIHS01"): SHA-256 of the type description of a message (its
// fields and the types they refer to) as the ROS 2 interface generator writes it in JSON. Iron and
// later (Jazzy) put it in every endpoint's USER_DATA as `typehash=RIHS01_<64 hex>;` and show it in
// `ros2 topic info -v`; matching does not depend on it (Humble has none). Computed from the
// message definitions of rosmsg/definitions.h, and checked by a test against the hashes ROS 2
// Jazzy prints.
#pragma once

#include <string>

#include "mapless/rosmsg/definitions.h"

namespace mapless::ros2 {

using rosmsg::ConcatenatedDefinition;
using rosmsg::FindMessage;
using rosmsg::KnownMessages;
using rosmsg::MsgDefinition;
using rosmsg::MsgField;
using rosmsg::TypeDescriptionJson;

// "RIHS01_<hex>" of a known message type; throws std::out_of_range for an unknown one.
std::string TypeHash(const std::string& type);

}  // namespace mapless::ros2

// ROS 2 on plain DDS (Cyclone DDS, Debian's 0.10): what the ROS 2 middleware (rmw) does that a ROS
// 2 peer relies on, done here without ROS 2 installed.
//  - Topics: a ROS name `/ns/cmd_vel` is the DDS topic `rt/ns/cmd_vel`; types are named
//    `<package>::msg::dds_::<Type>_` (ros2_msgs.idl); samples are CDR (XCDR1, little endian).
//  - QoS as ROS 2 sets it: sensor data (camera, odometry we read, debug image) best effort, keep
//    last 5; the default profile (cmd_vel, status, e-stop) reliable, keep last 10; the clock best
//    effort, keep last 1; all volatile.
//  - The domain: ROS_DOMAIN_ID (0 to 232, default 0). ROS_LOCALHOST_ONLY=1 (Humble) or
//    ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST / OFF (Jazzy) keep discovery and data on loopback,
//    as rmw_cyclonedds does. CYCLONEDDS_URI is honoured, as by any Cyclone program.
//  - The type hash: endpoints carry `typehash=RIHS01_<hex>;` in their USER_DATA, as Iron and
//    later (Jazzy) publish it (ros2_type_hash.h); Humble ignores it.
#pragma once

#include <dds/dds.h>

#include <string>

namespace mapless::ros2 {

// ROS_DOMAIN_ID, checked (InputError naming the variable).
int DomainId();

// The DDS topic of a resolved ROS topic name ("/ns/cmd_vel" -> "rt/ns/cmd_vel").
std::string DdsTopicName(const std::string& ros_name);

enum class Qos { kSensorData, kDefault, kClock };

// The process's DDS participant on the ROS domain (created on first use, deleted at exit).
// Throws std::runtime_error when Cyclone cannot start (its message included).
dds_entity_t Participant();

// A reader or writer of the ROS topic `ros_name` with type `desc`, the QoS of `qos` and the type
// hash of `ros_type` ("geometry_msgs/msg/Twist") in its USER_DATA. Throws std::runtime_error.
dds_entity_t MakeWriter(const dds_topic_descriptor_t* desc, const std::string& ros_name,
                        const std::string& ros_type, Qos qos);
dds_entity_t MakeReader(const dds_topic_descriptor_t* desc, const std::string& ros_name,
                        const std::string& ros_type, Qos qos, const dds_listener_t* listener);

// How many readers a writer has, and writers a reader has (matched, now).
int MatchedReaders(dds_entity_t writer);
int MatchedWriters(dds_entity_t reader);

// Deletes an entity (a reader, a writer) if it is one; 0 is no entity.
void Delete(dds_entity_t entity);

}  // namespace mapless::ros2

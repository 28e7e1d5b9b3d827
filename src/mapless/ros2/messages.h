// Writing and taking the ROS 2 messages mapless speaks, over the C types idlc generates from
// ros2_msgs.idl. Header stamps are builtin_interfaces/Time (seconds and nanoseconds).
#pragma once

#include <dds/dds.h>

#include <functional>
#include <string>

#include "mapless/core/pose.h"
#include "mapless/robot/sim_serve.h"
#include "ros2_msgs.h"

namespace mapless::ros2 {

builtin_interfaces_msg_dds__Time_ ToTime(Timestamp t_ns);
Timestamp FromTime(const builtin_interfaces_msg_dds__Time_& t);

// Each returns what dds_write returned (negative: an error).
dds_return_t WriteTwist(dds_entity_t writer, const Twist2& command);
dds_return_t WriteString(dds_entity_t writer, const std::string& text);
dds_return_t WriteBool(dds_entity_t writer, bool value);
dds_return_t WriteClock(dds_entity_t writer, Timestamp t_ns);
// nav_msgs/Odometry in frame `odom`, child `base_link` (REP-105).
dds_return_t WriteOdometry(dds_entity_t writer, Timestamp t_ns, const Pose2& pose);
// sensor_msgs/Image, or CompressedImage when image.compressed.
dds_return_t WriteImage(dds_entity_t writer, Timestamp t_ns, const std::string& frame_id,
                        const robot::CameraMessage& image);

// Takes every sample waiting on `reader` (loaned, valid data only) and hands each to `handle`,
// oldest first; returns how many.
template <typename T>
int TakeAll(dds_entity_t reader, const std::function<void(const T&)>& handle) {
  int taken = 0;
  while (true) {
    void* samples[8] = {nullptr};
    dds_sample_info_t infos[8];
    const dds_return_t n = dds_take(reader, samples, infos, 8, 8);
    if (n <= 0) break;
    for (dds_return_t i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      handle(*static_cast<const T*>(samples[i]));
      ++taken;
    }
    dds_return_loan(reader, samples, n);
  }
  return taken;
}

}  // namespace mapless::ros2

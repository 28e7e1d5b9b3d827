// The ROS messages of a recording, as plain fields: written as ROS 2 CDR (MCAP recordings), read
// from ROS 2 CDR (MCAP) or ROS 1 (bags). Only what mapless records and replays: camera images
// (raw and compressed), camera info, velocity commands, odometry and poses. The readers take
// untrusted bytes and throw InputError naming the message and field.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mapless/core/pose.h"
#include "mapless/rosmsg/wire.h"

namespace mapless::rosmsg {

// std_msgs/Header (ROS 1 adds a sequence number, read and dropped).
struct Header {
  Timestamp stamp_ns = 0;
  std::string frame_id;
};

// sensor_msgs/Image. `data` views the message's bytes.
struct ImageFields {
  Header header;
  std::uint32_t height = 0;
  std::uint32_t width = 0;
  std::string encoding;
  bool big_endian = false;
  std::uint32_t step = 0;
  std::string_view data;
};

// sensor_msgs/CompressedImage. `data` views the message's bytes.
struct CompressedImageFields {
  Header header;
  std::string format;
  std::string_view data;
};

// sensor_msgs/CameraInfo (without binning and region of interest, written as zero / full image).
struct CameraInfoFields {
  Header header;
  std::uint32_t height = 0;
  std::uint32_t width = 0;
  std::string distortion_model = "plumb_bob";
  std::vector<double> d;
  std::array<double, 9> k{};
  std::array<double, 9> r{};
  std::array<double, 12> p{};
};

// nav_msgs/Odometry on the ground plane: the pose's yaw from its quaternion, the twist's forward
// speed and turn rate (REP-103: x forward, z up).
struct OdometryFields {
  Header header;
  std::string child_frame_id;
  Pose2 pose;
  Twist2 twist;
};

// geometry_msgs/PoseStamped on the ground plane.
struct PoseStampedFields {
  Header header;
  Pose2 pose;
};

std::vector<std::uint8_t> EncodeImage(const ImageFields& m);
std::vector<std::uint8_t> EncodeCompressedImage(const CompressedImageFields& m);
std::vector<std::uint8_t> EncodeCameraInfo(const CameraInfoFields& m);
std::vector<std::uint8_t> EncodeTwist(const Twist2& m);
std::vector<std::uint8_t> EncodeOdometry(const OdometryFields& m);
std::vector<std::uint8_t> EncodePoseStamped(const PoseStampedFields& m);

ImageFields DecodeImage(std::string_view bytes, Wire wire);
CompressedImageFields DecodeCompressedImage(std::string_view bytes, Wire wire);
CameraInfoFields DecodeCameraInfo(std::string_view bytes, Wire wire);
Twist2 DecodeTwist(std::string_view bytes, Wire wire);
OdometryFields DecodeOdometry(std::string_view bytes, Wire wire);
PoseStampedFields DecodePoseStamped(std::string_view bytes, Wire wire);

}  // namespace mapless::rosmsg

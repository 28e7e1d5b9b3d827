// Camera images as robots send them (the fields of sensor_msgs/Image, or a compressed JPEG/PNG)
// turned into what a method needs: 8-bit grey, upright, at the method's size. Shared by every
// middleware adapter; the bytes come from the network, so every size is checked before use.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "mapless/robot/robot_file.h"

namespace mapless::robot {

// The encodings a raw image may have (sensor_msgs/image_encodings): mono8, mono16, rgb8, bgr8,
// rgba8, bgra8 (colour is converted to grey).
bool IsSupportedEncoding(const std::string& encoding);

// An 8-bit grey copy of a raw image; throws InputError naming what is wrong (an unsupported
// encoding, a size over io/limits.h, a step or data length that does not fit).
cv::Mat GreyFromRaw(const std::string& encoding, std::uint32_t width, std::uint32_t height,
                    std::uint32_t step, bool big_endian, std::string_view data);

// A grey image from a compressed one (`format` as in sensor_msgs/CompressedImage: "jpeg", "png",
// "mono8; jpeg compressed bgr8", ...); throws InputError.
cv::Mat GreyFromCompressed(const std::string& format, std::string_view data);

// Upright (the mount) and at `size` (area interpolation; 0x0: as it is).
cv::Mat PrepareFrame(const cv::Mat& grey, CameraMount mount, cv::Size size);

}  // namespace mapless::robot

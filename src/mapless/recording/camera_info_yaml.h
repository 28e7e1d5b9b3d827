// Camera intrinsics in the ROS camera_info YAML format (what camera_calibration writes and
// camera_info_manager reads: image_width, image_height, camera_name, camera_matrix,
// distortion_model, distortion_coefficients, rectification_matrix, projection_matrix; each matrix
// as {rows, cols, data}). mapless's methods need no calibration; given with --camera-info, the
// intrinsics go into recordings as sensor_msgs/CameraInfo with every frame.
#pragma once

#include <string>

#include "mapless/rosmsg/messages.h"

namespace mapless::recording {

// Throws InputError "FILE:LINE:COL: field: ..." on a missing or malformed field, a matrix whose
// rows x cols is not its data's length or not its required shape, a number that is not finite,
// or a focal length that is not positive. Absent optional fields: distortion none (empty, model
// "plumb_bob"), rectification the identity, projection [K | 0].
rosmsg::CameraInfoFields LoadCameraInfoYaml(const std::string& path);
rosmsg::CameraInfoFields ParseCameraInfoYaml(const std::string& text, const std::string& name);

// The same format back (camera_name "camera").
std::string FormatCameraInfoYaml(const rosmsg::CameraInfoFields& info);

}  // namespace mapless::recording

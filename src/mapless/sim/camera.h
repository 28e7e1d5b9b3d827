// Pinhole camera and its mount on the robot. Image coordinates follow OpenCV: x right, y down,
// pixel centres at integer coordinates. Camera frame: x right, y down, z along the optical axis.
// By default the optical axis is parallel to the robot's heading and passes through the robot's
// rotation axis (the funnel-lane assumption); `pitch_rad` > 0 tilts it down towards the ground
// (the visual-potential papers' downward-looking mount).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "mapless/core/pose.h"

namespace mapless::sim {

struct CameraModel {
  int width = 320;
  int height = 240;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;

  // Square pixels, principal point at the image centre, given horizontal field of view.
  static CameraModel FromFov(int width, int height, double hfov_rad);
  void Validate() const;

  // Projects a point in the camera frame; nullopt behind the camera (z <= 1e-9).
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_cam) const;
};

struct CameraMount {
  double height_m = 0.4;   // optical centre above the ground
  double pitch_rad = 0.0;  // downward tilt of the optical axis
  double forward_m = 0.0;  // optical centre ahead of the rotation axis
  double lateral_m = 0.0;  // optical centre to the left of the rotation axis
  void Validate() const;
};

// Rigid transform world_from_camera: p_world = rotation * p_cam + translation.
using Rigid3 = Eigen::Isometry3d;

Rigid3 RobotFromCamera(const CameraMount& mount);
Rigid3 WorldFromRobot(const Pose2& pose);
inline Rigid3 WorldFromCamera(const Pose2& robot, const CameraMount& mount) {
  return WorldFromRobot(robot) * RobotFromCamera(mount);
}

}  // namespace mapless::sim

#include "mapless/sim/camera.h"

#include <cmath>

#include "mapless/core/check.h"

namespace mapless::sim {

CameraModel CameraModel::FromFov(int width, int height, double hfov_rad) {
  CameraModel m;
  m.width = width;
  m.height = height;
  m.fx = 0.5 * width / std::tan(0.5 * hfov_rad);
  m.fy = m.fx;
  m.cx = 0.5 * (width - 1);
  m.cy = 0.5 * (height - 1);
  return m;
}

void CameraModel::Validate() const {
  MAPLESS_CHECK(width >= 16 && width <= 4096,
                "CameraModel.width = " << width << "; must be in [16, 4096]");
  MAPLESS_CHECK(height >= 16 && height <= 4096,
                "CameraModel.height = " << height << "; must be in [16, 4096]");
  MAPLESS_CHECK(fx > 0.0 && fy > 0.0,
                "CameraModel.fx, fy = " << fx << ", " << fy << "; must be > 0");
}

std::optional<Eigen::Vector2d> CameraModel::Project(const Eigen::Vector3d& p_cam) const {
  if (p_cam.z() <= 1e-9) return std::nullopt;
  return Eigen::Vector2d(fx * p_cam.x() / p_cam.z() + cx, fy * p_cam.y() / p_cam.z() + cy);
}

void CameraMount::Validate() const {
  MAPLESS_CHECK(height_m > 0.0 && height_m <= 100.0,
                "CameraMount.height_m = " << height_m << "; must be in (0, 100]");
  MAPLESS_CHECK(std::isfinite(forward_m) && std::isfinite(lateral_m) &&
                    std::abs(forward_m) <= 10.0 && std::abs(lateral_m) <= 10.0,
                "CameraMount.forward_m, lateral_m = " << forward_m << ", " << lateral_m
                                                      << "; each must be in [-10, 10]");
  MAPLESS_CHECK(std::abs(pitch_rad) < DegToRad(89.0),
                "CameraMount.pitch_deg = " << RadToDeg(pitch_rad) << "; must be in (-89, 89)");
}

Rigid3 RobotFromCamera(const CameraMount& mount) {
  // Columns: camera axes in the robot frame (x forward, y left, z up).
  const double c = std::cos(mount.pitch_rad);
  const double s = std::sin(mount.pitch_rad);
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0);   // image right = robot right
  r.col(1) = Eigen::Vector3d(-s, 0, -c);  // image down
  r.col(2) = Eigen::Vector3d(c, 0, -s);   // optical axis, tilted down by the pitch
  Rigid3 t = Rigid3::Identity();
  t.linear() = r;
  t.translation() = Eigen::Vector3d(mount.forward_m, mount.lateral_m, mount.height_m);
  return t;
}

Rigid3 WorldFromRobot(const Pose2& pose) {
  Rigid3 t = Rigid3::Identity();
  t.linear() = Eigen::AngleAxisd(pose.theta_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(pose.x_m, pose.y_m, 0.0);
  return t;
}

}  // namespace mapless::sim

// Planar rigid motion and velocity: the robot's state on the ground plane.
// Conventions: world frame x, y on the ground, z up; theta is the heading, counter-clockwise from
// the world x axis, in radians. Robot frame: x forward, y left, z up.
#pragma once

#include <cmath>
#include <cstdint>

namespace mapless {

inline constexpr double kPi = 3.14159265358979323846;

// Wraps an angle to (-pi, pi].
double WrapAngle(double angle_rad);

inline double DegToRad(double deg) { return deg * kPi / 180.0; }
inline double RadToDeg(double rad) { return rad * 180.0 / kPi; }
// The yaw (rotation about z) of a unit quaternion, and the quaternion of a yaw (REP-103: z up).
inline double YawFromQuaternion(double x, double y, double z, double w) {
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

// Pose of a frame on the plane: world_from_robot maps robot coordinates to world coordinates.
struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;

  // this * other: composes transforms (this = a_from_b, other = b_from_c gives a_from_c).
  Pose2 operator*(const Pose2& other) const;
  Pose2 Inverse() const;
  // Maps a point given in this frame into the parent frame.
  void Apply(double px, double py, double* out_x, double* out_y) const;
  double DistanceTo(const Pose2& other) const {
    return std::hypot(x_m - other.x_m, y_m - other.y_m);
  }
};

// Velocity of a differential-drive robot in its own frame.
struct Twist2 {
  double v_mps = 0.0;        // forward speed, m/s
  double omega_radps = 0.0;  // turn rate, rad/s, positive counter-clockwise (left)
};

// Time since the start of a run, in nanoseconds (Basalt's t_ns).
using Timestamp = std::int64_t;
inline constexpr Timestamp kNsPerSecond = 1'000'000'000;
inline double ToSeconds(Timestamp t_ns) { return static_cast<double>(t_ns) * 1e-9; }
inline Timestamp FromSeconds(double t_s) { return static_cast<Timestamp>(std::llround(t_s * 1e9)); }

// Integrates a constant twist for dt seconds from pose (exact arc, not Euler).
Pose2 IntegrateTwist(const Pose2& pose, const Twist2& twist, double dt_s);

}  // namespace mapless

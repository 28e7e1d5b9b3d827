#include "mapless/core/pose.h"

namespace mapless {

double WrapAngle(double angle_rad) {
  double a = std::fmod(angle_rad + kPi, 2.0 * kPi);
  if (a <= 0.0) a += 2.0 * kPi;
  return a - kPi;
}

Pose2 Pose2::operator*(const Pose2& other) const {
  Pose2 out;
  Apply(other.x_m, other.y_m, &out.x_m, &out.y_m);
  out.theta_rad = WrapAngle(theta_rad + other.theta_rad);
  return out;
}

Pose2 Pose2::Inverse() const {
  const double c = std::cos(theta_rad);
  const double s = std::sin(theta_rad);
  return Pose2{-c * x_m - s * y_m, s * x_m - c * y_m, WrapAngle(-theta_rad)};
}

void Pose2::Apply(double px, double py, double* out_x, double* out_y) const {
  const double c = std::cos(theta_rad);
  const double s = std::sin(theta_rad);
  *out_x = x_m + c * px - s * py;
  *out_y = y_m + s * px + c * py;
}

Pose2 IntegrateTwist(const Pose2& pose, const Twist2& twist, double dt_s) {
  const double dtheta = twist.omega_radps * dt_s;
  const double ds = twist.v_mps * dt_s;
  double dx = 0.0;
  double dy = 0.0;
  if (std::abs(dtheta) < 1e-9) {
    dx = ds;
    dy = 0.5 * ds * dtheta;
  } else {
    const double r = ds / dtheta;
    dx = r * std::sin(dtheta);
    dy = r * (1.0 - std::cos(dtheta));
  }
  return pose * Pose2{dx, dy, dtheta};
}

}  // namespace mapless

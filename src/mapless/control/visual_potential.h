// The visual potential field and its control law (Ohnishi & Imiya, Section 4). Pure functions on
// images: the dominant-plane map d (0/255), the planar flow u_hat and the calibrated pure
// translational / rotational planar flows.
//
// Image axes: x to the right, y down. The robot's forward direction is image "up", (0, -1): a
// downward-looking camera sees the ground stream down the image as the robot advances, and the
// attraction -u_hat then points up. Angles are positive to the left (counter-clockwise), like the
// robot's rotation.
#pragma once

#include <opencv2/core.hpp>

#include "mapless/core/pose.h"

namespace mapless::control {

struct VisualPotentialOptions {
  double sigma_fraction = 0.5;  // Gaussian sigma as a fraction of the image width (Eq. 9: half)
  int work_width_px = 80;       // the smoothing runs on the map resized to this width (speed; a
                                // sigma of half the image makes the result smooth anyway)
  double repulsion_gain = 1.0;  // weight of g against the flow (1: the paper's Eq. 11)
  double max_translation_mps = 0.2;  // T_m of Eq. 17
  double max_rotation_radps = 0.5;   // R_m of Eq. 17
  void Validate() const;
};

// g(x) = grad(G * d) (Eq. 8-10), CV_32FC2 at the map's size, in grey levels per pixel. It points
// from obstacles (0) towards free ground (255): the repulsion.
cv::Mat RepulsionField(const cv::Mat& plane_mask, const VisualPotentialOptions& options);

// Eq. 13: u_d = u_t cos(theta_d) + u_r sin(theta_d), theta_d the destination's direction relative
// to the robot's heading (positive: to the left).
cv::Mat DesiredFlow(const cv::Mat& translational, const cv::Mat& rotational, double theta_d_rad);

// Eq. 11 / 14: p = gain * g - u on the plane (d = 255), gain * g elsewhere.
cv::Mat PotentialField(const cv::Mat& plane_mask, const cv::Mat& repulsion,
                       const cv::Mat& attraction, const VisualPotentialOptions& options);

// Eq. 15: the mean of the potential over the region of interest (the whole field when empty).
cv::Vec2d ControlForce(const cv::Mat& potential, const cv::Rect& roi = {});

// Eq. 16-17: theta, the signed angle from the forward direction (0, -1) to the force (positive
// to the left); T = T_m cos(theta), R = R_m sin(theta). A force pointing backwards gives T < 0:
// the paper's law; callers that must not reverse clamp it.
struct PotentialCommand {
  double theta_rad = 0.0;
  Twist2 twist;
};
PotentialCommand CommandFromForce(const cv::Vec2d& force, const VisualPotentialOptions& options);

}  // namespace mapless::control

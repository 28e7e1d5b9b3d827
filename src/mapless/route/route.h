// The taught route of the funnel-lane method (Kassir et al., Section III): keyframes chosen when
// fewer than half of the tracked features survive, each with what the repeat phase needs: its
// features (keypoints and descriptors), a downscaled image, and the features tracked through the
// segment that ends at it, with their coordinates at both ends.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::route {

struct Keyframe {
  int index = 0;
  Timestamp t_ns = 0;
  cv::Mat thumbnail;                    // downscaled grey image
  std::vector<cv::KeyPoint> keypoints;  // in full-image pixels
  cv::Mat descriptors;                  // one row per keypoint
  // Features tracked from the previous keyframe to this one (empty for the first keyframe).
  std::vector<cv::Point2f> segment_start_px;
  std::vector<cv::Point2f> segment_end_px;
  // The robot's odometry pose (REP-105 odom frame) when the keyframe was taught, when the teach
  // had odometry: lets the repeat carry on through keyframes whose landmarks are gone.
  std::optional<Pose2> odometry;
};

struct Route {
  std::string detector = "orb";  // features::DetectorTypeName of the descriptors
  int image_width = 0;           // size of the images the features were measured in
  int image_height = 0;
  bool complete = false;  // false: the teach was interrupted (the keyframes are intact)
  std::vector<Keyframe> keyframes;
};

}  // namespace mapless::route

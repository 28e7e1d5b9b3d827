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

// A route's visits (repeat --learn, follow --learn, route merge): a million repeats is 30 a day for
// a century; the count must never reach int's end (2^31-1 visits overflowed on the next visit).
inline constexpr int kMaxRouteVisits = 1'000'000;

// A view of a keyframe's place learned on a later visit (issue 45; navigation/experiences.h): its
// features, and the horizontal offset the repeat measured when it learned it (x in this view - x
// in the taught view), which maps its features back into the taught view's coordinates.
struct KeyframeView {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  double offset_px = 0.0;
  int learned_at = 0;  // the route's visit that learned it (Route::visits then)
  int last_used = 0;   // the last visit at which it was the view the repeat steered by
  std::string file;    // where it is stored in the route directory; "" until it is
};

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
  std::vector<KeyframeView> views;  // learned on later visits (empty: the taught view alone)
};

struct Route {
  std::string detector = "orb";  // features::DetectorTypeName of the descriptors
  int image_width = 0;           // size of the images the features were measured in
  int image_height = 0;
  bool complete = false;  // false: the teach was interrupted (the keyframes are intact)
  int visits = 0;         // repeats that learned views (route_store.h: SaveViews)
  std::vector<Keyframe> keyframes;
};

}  // namespace mapless::route

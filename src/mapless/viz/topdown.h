// Top-down pictures of a simulated world with paths drawn on it: walls, boxes, cylinders and
// posters as seen from above, a metre grid, a scale bar and a legend. Pure drawing: returns an
// image; writing it is the caller's business.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/core/pose.h"
#include "mapless/sim/world.h"

namespace mapless::viz {

struct TopDownPath {
  std::vector<Pose2> poses;
  cv::Scalar color{0, 0, 255};  // BGR
  std::string label;
};

struct TopDownOptions {
  double pixels_per_m = 60.0;  // reduced automatically so that the picture fits max_side_px
  int max_side_px = 1400;
  double margin_m = 0.8;
};

// Draws the world and the paths; `markers` are drawn as small circles (e.g. destinations).
cv::Mat DrawTopDown(const sim::World& world, const std::vector<TopDownPath>& paths,
                    const std::vector<Eigen::Vector2d>& markers = {},
                    const TopDownOptions& options = {});

}  // namespace mapless::viz

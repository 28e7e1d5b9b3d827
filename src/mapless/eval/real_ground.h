// `mapless eval ground` (issue 66): the ground (dominant plane) from the flow between consecutive
// frames, against hand-labelled masks, by mapless and by a stock baseline on the same flow in the
// same run. Layout: DIR_FRAMES/NAME (file-name order = time order) and DIR_MASKS/NAME (255 or any
// value > 127 where the label is ground: road, pavement); every frame that has a mask and a next
// frame is evaluated. The IoU is over the bottom half of the image (a forward camera's horizon is
// near the middle), averaged over the frames.
#pragma once

#include <string>
#include <vector>

#include "mapless/flow/flow.h"
#include "mapless/ground/dominant_plane.h"

namespace mapless::eval {

struct GroundMethodFigures {
  std::string method;
  int pairs = 0;
  double mean_iou = 0.0;
  double plane_ms = 0.0;  // median per pair, the plane from the flow (the flow not counted)
};

struct GroundEvalFigures {
  int pairs = 0;
  double flow_ms = 0.0;                      // median per pair, the flow both methods share
  std::vector<GroundMethodFigures> methods;  // mapless first
};

struct GroundEvalOptions {
  flow::FlowOptions flow;              // mapless ground's: DIS medium
  ground::DominantPlaneOptions plane;  // mapless ground's defaults (MaplessGroundOptions)
  double iou_top_fraction = 0.5;       // IoU over the rows below this fraction of the height
  double baseline_threshold_px = 3.0;  // cv::findHomography's RANSAC threshold (its default)
  bool baselines = true;
};

// The options `mapless ground` uses by default (bottom-half region, adaptive tolerance).
GroundEvalOptions DefaultGroundEvalOptions();

GroundEvalFigures EvalGround(const std::string& frames_dir, const std::string& masks_dir,
                             const GroundEvalOptions& options);

}  // namespace mapless::eval

// `mapless eval shift` (issue 66): the horizontal shift between views of the same place taken in
// different sessions, by mapless's estimator and by stock baselines on the same images in the same
// run. Two dataset layouts (docs/real_data.md):
//   - sessions: DIR/SSPP.png and DIR/offsets.txt (eval/experiences.h); every ordered pair of two
//     sessions of a place, truth = offset(current) - offset(reference);
//   - two folders: DIR/summer/NAME, DIR/winter/NAME and DIR/dx.txt, lines "NAME dx_px" with
//     dx = x_in_winter - x_in_summer; both directions of every listed name.
// A pair is right when the estimate is ok and within the tolerance of the truth.
#pragma once

#include <string>
#include <vector>

#include "mapless/features/shift.h"

namespace mapless::eval {

struct ShiftPair {
  int reference = 0;  // indices into ShiftDataset::images
  int current = 0;
  double truth_dx_px = 0.0;  // x_in_current - x_in_reference
};

struct ShiftDataset {
  std::string dir;
  std::string layout;  // "sessions" or "two folders"
  std::vector<std::string> images;
  std::vector<ShiftPair> pairs;
};

// Either layout (sessions when DIR/offsets.txt exists); throws InputError naming the file and
// line, or the image, when something is missing or malformed. Images are not read here.
ShiftDataset LoadShiftDataset(const std::string& dir);

struct ShiftMethodFigures {
  std::string method;
  int pairs = 0;
  int within = 0;  // ok and within the tolerance
  int not_ok = 0;  // the estimator said it could not tell
  double fraction = 0.0;
  double extract_ms = 0.0;  // median per image
  double match_ms = 0.0;    // median per pair (matching and voting)
  double pair_ms = 0.0;     // both images and the match: 2 * extract_ms + match_ms
};

struct ShiftEvalFigures {
  int images = 0;
  int pairs = 0;
  double tolerance_px = 17.5;
  std::vector<ShiftMethodFigures> methods;  // mapless first, then the baselines
};

struct ShiftEvalOptions {
  features::ShiftOptions shift;  // mapless's estimator
  double tolerance_px = 17.5;
  bool baselines = true;
};

// The baselines, the recipe of issue 66 (stock OpenCV, 1600 keypoints, cross-checked matches,
// a histogram vote on dx): "orb" (cv::ORB) and "fast_sift" (cv::FastFeatureDetector, the 1600
// strongest, cv::SIFT descriptors).
ShiftEvalFigures EvalShift(const ShiftDataset& data, const ShiftEvalOptions& options);

}  // namespace mapless::eval

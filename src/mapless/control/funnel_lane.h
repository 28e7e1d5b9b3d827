// Funnel-lane control of a robot towards the destination keyframe of its segment, from the
// horizontal image coordinates of matched features alone (no calibration, no geometry).
//
// Implements Kassir, Palhang & Ahmadzadeh, "Qualitative vision-based navigation based on sloped
// funnel lane concept" (../shared/papers/sloped_funnel_lane_teach_and_repeat.md):
//  - the standard funnel lane of Chen & Birchfield (Section IV, constraints (1)-(2), intersection
//    over features, bang-bang control with a fixed turn rate), the baseline;
//  - the sloped funnel lane (Section V, constraint (5), slopes around y and x, turn type down to
//    rotation in place);
//  - the keyframe switching criterion (Section VI: StdRatio > 1 and ED < threshold), and the
//    MSE criterion of Chen & Birchfield for comparison.
//
// Coordinates `u` are x image coordinates relative to the principal point (x - cx), in pixels.
// Turn commands follow Twist2: positive omega turns left.
#pragma once

#include <vector>

#include "mapless/core/pose.h"

namespace mapless::control {

// One feature seen now (u_c) and in the destination keyframe (u_j).
struct FeaturePair {
  double u_current_px = 0.0;
  double u_destination_px = 0.0;
};

// How the spread of x coordinates is measured for StdRatio: the paper's standard deviation, or the
// median absolute deviation (scaled to match it for Gaussian data), which outliers cannot inflate.
enum class Spread { kStdDev, kMad };

enum class TurnCommand { kStraight, kLeft, kRight };
const char* TurnCommandName(TurnCommand command);

// ---- Standard funnel lane (Section IV) ---------------------------------------------------------

struct StandardFunnelLaneOptions {
  double forward_speed_mps = 0.2;  // constant forward speed (bang-bang control)
  double turn_rate_radps = 0.3;    // fixed turn rate of a left or right command
  void Validate() const;
};

struct StandardFunnelLaneResult {
  TurnCommand command = TurnCommand::kStraight;
  int inside = 0;       // features whose constraints (1) and (2) both hold
  int left_votes = 0;   // features outside their funnel lane asking for a left turn
  int right_votes = 0;  // ... asking for a right turn
  Twist2 twist;
};

// Per feature: inside its funnel lane when |u_c| < |u_j| (1) and sign(u_c) = sign(u_j) (2).
// A feature outside asks to turn towards its lane: for u_j > 0, u_c >= u_j (too far right) asks
// right and u_c <= 0 asks left; mirrored for u_j < 0. The robot is in the final funnel lane (the
// intersection) when no feature asks; otherwise it turns the way most features ask.
StandardFunnelLaneResult ComputeStandardFunnelLane(const std::vector<FeaturePair>& features,
                                                   const StandardFunnelLaneOptions& options);

// ---- Sloped funnel lane (Section V) ------------------------------------------------------------

struct SlopedFunnelLaneOptions {
  double beta = 1.0;             // slope around y: beta * (1 - sigma_c / sigma_j)
  double gamma = 1.0;            // slope around x: gamma * sum over sides of (mu_j - mu_c)/|mu_j|
  double turn_threshold = 0.05;  // |slope_x| above which the robot turns
  double slope_x_for_full_turn = 1.0;  // |slope_x| at which the turn rate reaches its maximum
  // Floor on |mu_j| in the slope around x, px: a side whose destination median is near the image
  // centre would otherwise make the slope explode (not in the paper; 0 disables it).
  double min_median_px = 20.0;
  double slope_y_for_full_speed = 0.15;  // slope_y at which a turning robot keeps full speed
  double max_speed_mps = 0.2;            // forward speed when going straight
  double max_turn_rate_radps = 0.5;      // turn rate at full turn
  Spread spread = Spread::kStdDev;       // spread used for StdRatio
  void Validate() const;
};

struct SlopedFunnelLaneResult {
  bool ok = false;         // false: fewer than 2 features (no standard deviation)
  double std_ratio = 0.0;  // sigma_c / sigma_j, constraint (5) holds when < 1
  double slope_y = 0.0;    // beta * (1 - std_ratio): the type of turn
  double slope_x = 0.0;    // the decision to turn: > 0 left, < 0 right
  int left_features = 0;   // classified by their side in the destination keyframe
  int right_features = 0;
  TurnCommand command = TurnCommand::kStraight;
  Twist2 twist;
};

// Slope around x from the medians of the left and right features (each side normalised by its
// destination median, and only the sides that have features); slope around y from the ratio of the
// standard deviations of all features. Control (Section V-A): straight at full speed while
// |slope_x| <= turn_threshold; otherwise turn towards sign(slope_x) with a rate growing with
// |slope_x| and a forward speed growing with slope_y, so that slope_y near 0 gives a rotation in
// place and a large slope_y a wide turn.
SlopedFunnelLaneResult ComputeSlopedFunnelLane(const std::vector<FeaturePair>& features,
                                               const SlopedFunnelLaneOptions& options);

// ---- Keyframe switching (Section VI) -----------------------------------------------------------

struct SwitchOptions {
  double max_ed_px = 12.0;     // ED threshold: |median u_c - median u_j|
  double min_std_ratio = 1.0;  // StdRatio must exceed this (the robot reached the keyframe)
  Spread spread = Spread::kStdDev;
  void Validate() const;
};

struct SwitchDecision {
  bool switch_now = false;
  double std_ratio = 0.0;  // sigma_c / sigma_j
  double ed_px = 0.0;      // |median(u_c) - median(u_j)|
};

// Switch to the next segment when, against the destination keyframe, StdRatio > min_std_ratio
// (the current features spread at least as wide as the keyframe's) and ED < max_ed_px.
SwitchDecision CheckSwitch(const std::vector<FeaturePair>& features, const SwitchOptions& options);

// ---- The route's end (not in the paper) --------------------------------------------------------

// One feature matched between the current image and the destination keyframe, both coordinates.
struct FeaturePoint {
  double x_current_px = 0.0;
  double y_current_px = 0.0;
  double x_destination_px = 0.0;
  double y_destination_px = 0.0;
};

struct LocalScaleOptions {
  // Pairs of features whose keyframe positions are this far apart (px) are compared: near enough
  // to lie on one object (one depth), far enough for the pixel noise to matter little.
  double min_pair_px = 6.0;
  double max_pair_px = 40.0;
  int min_pairs = 20;  // fewer: no estimate
  void Validate() const;
};

struct LocalScale {
  bool ok = false;
  double ratio = 0.0;  // median over pairs of |p_c,a - p_c,b| / |p_j,a - p_j,b|
  int pairs = 0;
};

// How much larger the scene looks now than in the destination keyframe, measured object by object:
// the median over nearby feature pairs of the ratio of their image distances. For two points at
// one depth the ratio is Z_keyframe / Z_now whatever the robot's lateral offset, so the median
// crosses 1 where the robot reaches the keyframe along its heading, also off the taught path.
// StdRatio mixes all depths: off to one side, the nearer side's features spread wider and it
// crosses 1 up to 0.7 m early (see docs/teach_and_repeat.md).
LocalScale MeasureLocalScale(const std::vector<FeaturePoint>& features,
                             const LocalScaleOptions& options);

// Chen & Birchfield's criterion: switch when the mean squared error between current and
// destination coordinates, after decreasing, increases for `rising_frames` frames in a row.
class MseSwitch {
 public:
  explicit MseSwitch(int rising_frames = 2) : rising_frames_(rising_frames) {}
  // Feeds one frame; true when the segment should switch. Call Reset() on a new segment.
  bool Update(const std::vector<FeaturePair>& features);
  void Reset();
  double last_mse() const { return last_mse_; }

 private:
  int rising_frames_;
  int rising_ = 0;
  double last_mse_ = -1.0;
  bool saw_decrease_ = false;
};

// Statistics used above, exposed for tests and logs.
double StdDev(const std::vector<double>& values);
double Mad(const std::vector<double>& values);  // 1.4826 * median |v - median(v)|
double Median(std::vector<double> values);

}  // namespace mapless::control

#include "mapless/control/funnel_lane.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"

namespace mapless::control {

const char* TurnCommandName(TurnCommand command) {
  switch (command) {
    case TurnCommand::kStraight:
      return "straight";
    case TurnCommand::kLeft:
      return "left";
    case TurnCommand::kRight:
      return "right";
  }
  return "?";
}

double StdDev(const std::vector<double>& values) {
  if (values.size() < 2) return 0.0;
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= static_cast<double>(values.size());
  double var = 0.0;
  for (double v : values) var += (v - mean) * (v - mean);
  return std::sqrt(var / static_cast<double>(values.size()));
}

double Mad(const std::vector<double>& values) {
  if (values.size() < 2) return 0.0;
  const double m = Median(values);
  std::vector<double> dev;
  dev.reserve(values.size());
  for (double v : values) dev.push_back(std::abs(v - m));
  return 1.4826 * Median(dev);
}

namespace {
double SpreadOf(const std::vector<double>& values, Spread spread) {
  return spread == Spread::kStdDev ? StdDev(values) : Mad(values);
}
}  // namespace

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (values.size() % 2 == 1) return *mid;
  const double upper = *mid;
  const double lower = *std::max_element(values.begin(), mid);
  return 0.5 * (lower + upper);
}

void StandardFunnelLaneOptions::Validate() const {
  MAPLESS_CHECK(forward_speed_mps > 0.0, "StandardFunnelLaneOptions.forward_speed_mps = "
                                             << forward_speed_mps << "; must be > 0");
  MAPLESS_CHECK(turn_rate_radps > 0.0, "StandardFunnelLaneOptions.turn_rate_radps = "
                                           << turn_rate_radps << "; must be > 0");
}

StandardFunnelLaneResult ComputeStandardFunnelLane(const std::vector<FeaturePair>& features,
                                                   const StandardFunnelLaneOptions& options) {
  StandardFunnelLaneResult r;
  for (const FeaturePair& f : features) {
    const double uc = f.u_current_px;
    const double uj = f.u_destination_px;
    // Eq. (1) |u_c| < |u_j| and Eq. (2) sign(u_c) = sign(u_j).
    const bool c1 = std::abs(uc) < std::abs(uj);
    const bool c2 = (uc > 0.0 && uj > 0.0) || (uc < 0.0 && uj < 0.0);
    if (c1 && c2) {
      ++r.inside;
      continue;
    }
    if (uj == 0.0) continue;  // a feature on the optical axis bounds no lane
    // Outside: turning left moves image points right. A right-side feature (u_j > 0) that is too
    // far right (u_c >= u_j) asks for a right turn; one that crossed to the left (u_c <= 0) asks
    // for a left turn. Mirrored for left-side features.
    if (uj > 0.0) {
      if (uc >= uj)
        ++r.right_votes;
      else
        ++r.left_votes;
    } else {
      if (uc <= uj)
        ++r.left_votes;
      else
        ++r.right_votes;
    }
  }
  if (r.left_votes > r.right_votes)
    r.command = TurnCommand::kLeft;
  else if (r.right_votes > r.left_votes)
    r.command = TurnCommand::kRight;
  r.twist.v_mps = options.forward_speed_mps;
  r.twist.omega_radps = r.command == TurnCommand::kLeft    ? options.turn_rate_radps
                        : r.command == TurnCommand::kRight ? -options.turn_rate_radps
                                                           : 0.0;
  return r;
}

void SlopedFunnelLaneOptions::Validate() const {
  MAPLESS_CHECK(beta > 0.0, "SlopedFunnelLaneOptions.beta = " << beta << "; must be > 0");
  MAPLESS_CHECK(gamma > 0.0, "SlopedFunnelLaneOptions.gamma = " << gamma << "; must be > 0");
  MAPLESS_CHECK(turn_threshold >= 0.0,
                "SlopedFunnelLaneOptions.turn_threshold = " << turn_threshold << "; must be >= 0");
  MAPLESS_CHECK(slope_x_for_full_turn > turn_threshold,
                "SlopedFunnelLaneOptions.slope_x_for_full_turn = " << slope_x_for_full_turn
                                                                   << "; must be > turn_threshold");
  MAPLESS_CHECK(slope_y_for_full_speed > 0.0, "SlopedFunnelLaneOptions.slope_y_for_full_speed = "
                                                  << slope_y_for_full_speed << "; must be > 0");
  MAPLESS_CHECK(min_median_px >= 0.0,
                "SlopedFunnelLaneOptions.min_median_px = " << min_median_px << "; must be >= 0");
  MAPLESS_CHECK(max_speed_mps > 0.0,
                "SlopedFunnelLaneOptions.max_speed_mps = " << max_speed_mps << "; must be > 0");
  MAPLESS_CHECK(max_turn_rate_radps > 0.0, "SlopedFunnelLaneOptions.max_turn_rate_radps = "
                                               << max_turn_rate_radps << "; must be > 0");
}

SlopedFunnelLaneResult ComputeSlopedFunnelLane(const std::vector<FeaturePair>& features,
                                               const SlopedFunnelLaneOptions& options) {
  SlopedFunnelLaneResult r;
  if (features.size() < 2) return r;
  std::vector<double> uc_all, uj_all, uc_left, uj_left, uc_right, uj_right;
  for (const FeaturePair& f : features) {
    uc_all.push_back(f.u_current_px);
    uj_all.push_back(f.u_destination_px);
    // Left or right of the destination keyframe's principal point.
    if (f.u_destination_px < 0.0) {
      uc_left.push_back(f.u_current_px);
      uj_left.push_back(f.u_destination_px);
    } else if (f.u_destination_px > 0.0) {
      uc_right.push_back(f.u_current_px);
      uj_right.push_back(f.u_destination_px);
    }
  }
  r.left_features = static_cast<int>(uc_left.size());
  r.right_features = static_cast<int>(uc_right.size());
  const double sigma_j = SpreadOf(uj_all, options.spread);
  if (sigma_j <= 1e-9) return r;
  r.ok = true;
  // Eq. (5) and the slope around y.
  r.std_ratio = SpreadOf(uc_all, options.spread) / sigma_j;
  r.slope_y = options.beta * (1.0 - r.std_ratio);
  // Slope around x: the sum of the two sides' normalised median offsets (one side if the other
  // has no features).
  double slope_x = 0.0;
  if (!uc_left.empty()) {
    const double mu_j = Median(uj_left);
    slope_x += (mu_j - Median(uc_left)) / std::max(std::abs(mu_j), options.min_median_px);
  }
  if (!uc_right.empty()) {
    const double mu_j = Median(uj_right);
    slope_x += (mu_j - Median(uc_right)) / std::max(std::abs(mu_j), options.min_median_px);
  }
  r.slope_x = options.gamma * slope_x;
  // Section V-A: no slope around x, go straight whatever the slope around y.
  if (std::abs(r.slope_x) <= options.turn_threshold) {
    r.command = TurnCommand::kStraight;
    r.twist = Twist2{options.max_speed_mps, 0.0};
    return r;
  }
  r.command = r.slope_x > 0.0 ? TurnCommand::kLeft : TurnCommand::kRight;
  // The turn rate grows with |slope_x|; the forward speed with slope_y (near 0: rotate in place).
  const double turn = std::clamp((std::abs(r.slope_x) - options.turn_threshold) /
                                     (options.slope_x_for_full_turn - options.turn_threshold),
                                 0.0, 1.0);
  const double speed = std::clamp(r.slope_y / options.slope_y_for_full_speed, 0.0, 1.0);
  r.twist.v_mps = options.max_speed_mps * speed;
  r.twist.omega_radps = std::copysign(options.max_turn_rate_radps * turn, r.slope_x);
  return r;
}

void SwitchOptions::Validate() const {
  MAPLESS_CHECK(max_ed_px > 0.0, "SwitchOptions.max_ed_px = " << max_ed_px << "; must be > 0");
  MAPLESS_CHECK(min_std_ratio > 0.0,
                "SwitchOptions.min_std_ratio = " << min_std_ratio << "; must be > 0");
}

SwitchDecision CheckSwitch(const std::vector<FeaturePair>& features, const SwitchOptions& options) {
  SwitchDecision d;
  if (features.size() < 2) return d;
  std::vector<double> uc, uj;
  for (const FeaturePair& f : features) {
    uc.push_back(f.u_current_px);
    uj.push_back(f.u_destination_px);
  }
  const double sigma_j = SpreadOf(uj, options.spread);
  if (sigma_j <= 1e-9) return d;
  d.std_ratio = SpreadOf(uc, options.spread) / sigma_j;
  d.ed_px = std::abs(Median(uc) - Median(uj));
  d.switch_now = d.std_ratio > options.min_std_ratio && d.ed_px < options.max_ed_px;
  return d;
}

void LocalScaleOptions::Validate() const {
  MAPLESS_CHECK(min_pair_px > 0.0,
                "LocalScaleOptions.min_pair_px = " << min_pair_px << "; must be > 0");
  MAPLESS_CHECK(max_pair_px > min_pair_px,
                "LocalScaleOptions.max_pair_px = " << max_pair_px << "; must be > min_pair_px");
  MAPLESS_CHECK(min_pairs >= 1, "LocalScaleOptions.min_pairs = " << min_pairs << "; must be >= 1");
}

LocalScale MeasureLocalScale(const std::vector<FeaturePoint>& features,
                             const LocalScaleOptions& options) {
  LocalScale s;
  std::vector<double> log_ratios;
  const double min2 = options.min_pair_px * options.min_pair_px;
  const double max2 = options.max_pair_px * options.max_pair_px;
  for (std::size_t a = 0; a < features.size(); ++a) {
    const FeaturePoint& fa = features[a];
    for (std::size_t b = a + 1; b < features.size(); ++b) {
      const FeaturePoint& fb = features[b];
      const double djx = fa.x_destination_px - fb.x_destination_px;
      const double djy = fa.y_destination_px - fb.y_destination_px;
      const double dj2 = djx * djx + djy * djy;
      if (dj2 < min2 || dj2 > max2) continue;
      const double dcx = fa.x_current_px - fb.x_current_px;
      const double dcy = fa.y_current_px - fb.y_current_px;
      const double dc2 = dcx * dcx + dcy * dcy;
      if (dc2 <= 0.0) continue;
      log_ratios.push_back(0.5 * std::log(dc2 / dj2));
    }
  }
  s.pairs = static_cast<int>(log_ratios.size());
  if (s.pairs < options.min_pairs) return s;
  s.ok = true;
  s.ratio = std::exp(Median(std::move(log_ratios)));
  return s;
}

bool MseSwitch::Update(const std::vector<FeaturePair>& features) {
  if (features.empty()) return false;
  double mse = 0.0;
  for (const FeaturePair& f : features) {
    const double e = f.u_current_px - f.u_destination_px;
    mse += e * e;
  }
  mse /= static_cast<double>(features.size());
  if (last_mse_ >= 0.0 && mse < last_mse_) saw_decrease_ = true;
  rising_ = (last_mse_ >= 0.0 && mse > last_mse_) ? rising_ + 1 : 0;
  last_mse_ = mse;
  return saw_decrease_ && rising_ >= rising_frames_;
}

void MseSwitch::Reset() {
  rising_ = 0;
  last_mse_ = -1.0;
  saw_decrease_ = false;
}

}  // namespace mapless::control

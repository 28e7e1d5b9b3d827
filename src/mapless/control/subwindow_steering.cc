#include "mapless/control/subwindow_steering.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "mapless/core/check.h"

namespace mapless::control {
namespace {

struct Point {
  double x = 0.0;
  double y = 0.0;
};

struct Line {
  bool ok = false;
  double slope = 0.0;
  double intercept = 0.0;
};

Line FitLine(const std::vector<Point>& points) {
  Line line;
  const double n = static_cast<double>(points.size());
  if (points.size() < 2) return line;
  double sx = 0.0;
  double sy = 0.0;
  for (const Point& p : points) {
    sx += p.x;
    sy += p.y;
  }
  const double mx = sx / n;
  const double my = sy / n;
  double sxx = 0.0;
  double sxy = 0.0;
  for (const Point& p : points) {
    sxx += (p.x - mx) * (p.x - mx);
    sxy += (p.x - mx) * (p.y - my);
  }
  if (sxx < 1e-9) return line;  // all points on one query window: no slope
  line.ok = true;
  line.slope = sxy / sxx;
  line.intercept = my - line.slope * mx;
  return line;
}

double Rms(const std::vector<Point>& points, const Line& line) {
  double sum = 0.0;
  for (const Point& p : points) {
    const double r = p.y - (line.slope * p.x + line.intercept);
    sum += r * r;
  }
  return points.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(points.size()));
}

struct Candidate {
  bool ok = false;
  std::string name;
  Line line;
  int inliers = 0;
  int outliers = 0;
  double rms = 0.0;
  int span = 0;  // number of query windows the fit covers
};

// Fits a line to `points`, removing the worst point while it lies further than `threshold`.
Candidate FitWithoutOutliers(std::vector<Point> points, double threshold) {
  Candidate candidate;
  const int total = static_cast<int>(points.size());
  Line line = FitLine(points);
  while (line.ok && points.size() > 2) {
    std::size_t worst = 0;
    double worst_r = -1.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double r = std::abs(points[i].y - (line.slope * points[i].x + line.intercept));
      if (r > worst_r) {
        worst_r = r;
        worst = i;
      }
    }
    if (worst_r <= threshold) break;
    points.erase(points.begin() + static_cast<std::ptrdiff_t>(worst));
    line = FitLine(points);
  }
  if (!line.ok) return candidate;
  candidate.ok = true;
  candidate.line = line;
  candidate.inliers = static_cast<int>(points.size());
  candidate.outliers = total - candidate.inliers;
  candidate.rms = Rms(points, line);
  return candidate;
}

const char kLetters[] = "ABCDE";

}  // namespace

void SubWindowSteeringOptions::Validate() const {
  MAPLESS_CHECK(outlier_windows > 0.0, "SubWindowSteeringOptions.outlier_windows = "
                                           << outlier_windows << "; must be > 0");
  MAPLESS_CHECK(outlier_fraction_of_slope >= 0.0,
                "SubWindowSteeringOptions.outlier_fraction_of_slope = " << outlier_fraction_of_slope
                                                                        << "; must be >= 0");
  MAPLESS_CHECK(
      slope_tolerance > 0.0 && slope_tolerance < 1.0,
      "SubWindowSteeringOptions.slope_tolerance = " << slope_tolerance << "; must be in (0, 1)");
  MAPLESS_CHECK(min_inliers >= 2,
                "SubWindowSteeringOptions.min_inliers = " << min_inliers << "; must be >= 2");
  MAPLESS_CHECK(turn_gain_radps_per_px >= 0.0, "SubWindowSteeringOptions.turn_gain_radps_per_px = "
                                                   << turn_gain_radps_per_px << "; must be >= 0");
  MAPLESS_CHECK(max_turn_rate_radps > 0.0, "SubWindowSteeringOptions.max_turn_rate_radps = "
                                               << max_turn_rate_radps << "; must be > 0");
  MAPLESS_CHECK(max_speed_mps >= 0.0,
                "SubWindowSteeringOptions.max_speed_mps = " << max_speed_mps << "; must be >= 0");
  MAPLESS_CHECK(shift_for_stop_px > 0.0, "SubWindowSteeringOptions.shift_for_stop_px = "
                                             << shift_for_stop_px << "; must be > 0");
  MAPLESS_CHECK(min_speed_fraction >= 0.0 && min_speed_fraction <= 1.0,
                "SubWindowSteeringOptions.min_speed_fraction = " << min_speed_fraction
                                                                 << "; must be in [0, 1]");
}

SubWindowSteering ComputeSubWindowSteering(const std::vector<WindowCorrespondence>& matches,
                                           int window_count, int step_px,
                                           const SubWindowSteeringOptions& options) {
  options.Validate();
  MAPLESS_CHECK(window_count >= 5,
                "sub-window steering: window_count = " << window_count << "; must be >= 5");
  MAPLESS_CHECK(step_px >= 1, "sub-window steering: step_px = " << step_px << "; must be >= 1");
  SubWindowSteering result;
  const double expected_slope = (window_count - 1) / 4.0;
  const double threshold =
      std::max(options.outlier_windows, options.outlier_fraction_of_slope * expected_slope);
  for (const WindowCorrespondence& m : matches) {
    MAPLESS_CHECK(
        m.query >= 0 && m.query < 5 && m.stored >= 0 && m.stored < window_count,
        "sub-window steering: correspondence (" << m.query << ", " << m.stored << ") out of range");
  }

  // Step 1: the seven fits of the paper (first 2, 3, 4 windows, all, last 4, 3, 2).
  constexpr std::array<std::array<int, 2>, 7> kRanges{
      {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 4}, {2, 4}, {3, 4}}};
  Candidate best;
  Candidate left_half;   // A-C
  Candidate right_half;  // C-E
  for (const auto& range : kRanges) {
    std::vector<Point> points;
    for (const WindowCorrespondence& m : matches) {
      if (m.query >= range[0] && m.query <= range[1]) {
        points.push_back({static_cast<double>(m.query), static_cast<double>(m.stored)});
      }
    }
    // Step 4: outliers removed before the final regression.
    Candidate c = FitWithoutOutliers(points, threshold);
    if (!c.ok || c.inliers < options.min_inliers) continue;
    if (std::abs(c.line.slope - expected_slope) > options.slope_tolerance * expected_slope)
      continue;
    c.span = range[1] - range[0] + 1;
    c.name = std::string(1, kLetters[range[0]]) + "-" + std::string(1, kLetters[range[1]]);
    // Step 2: most correspondences, then the lowest residual, then the slope nearest the
    // expected one.
    const auto key = [&](const Candidate& k) {
      return std::make_tuple(k.inliers, -std::round(k.rms * 10.0) / 10.0,
                             -std::abs(k.line.slope - expected_slope), k.span);
    };
    if (!best.ok || key(c) > key(best)) best = c;
    if (range[0] == 0 && range[1] == 2) left_half = c;
    if (range[0] == 2 && range[1] == 4) right_half = c;
  }
  // Not in the paper: near objects on one side (a parked car passed closer than during the teach)
  // look bigger and bend that side's correspondences; the steering, read from all windows, then
  // turns towards them, which makes them bigger still. When both halves give a fit, the ordinate
  // is read from the half whose slope is nearer the expected one (the side that does not loom).
  if (options.prefer_undistorted_half && left_half.ok && right_half.ok) {
    best = std::abs(left_half.line.slope - expected_slope) <=
                   std::abs(right_half.line.slope - expected_slope)
               ? left_half
               : right_half;
  }
  if (!best.ok) {
    result.reason =
        "no consistent sub-window fit (" + std::to_string(matches.size()) + " correspondences)";
    return result;
  }

  // Step 3: the ordinate, read at the centre window C relative to its aligned index.
  result.ok = true;
  result.fit = best.name;
  result.inliers = best.inliers;
  result.outliers = static_cast<int>(matches.size()) - best.inliers;
  result.slope = best.line.slope;
  result.shift_windows = best.line.slope * 2.0 + best.line.intercept - 2.0 * expected_slope;
  result.shift_px = result.shift_windows * step_px;
  result.residual_rms = best.rms;
  result.confidence = std::clamp(static_cast<double>(best.inliers) /
                                     std::max<double>(1.0, static_cast<double>(matches.size())) *
                                     std::exp(-best.rms / threshold),
                                 0.0, 1.0);
  result.twist = SteeringTwist(result.shift_px, options);
  return result;
}

Twist2 SteeringTwist(double shift_px, const SubWindowSteeringOptions& options) {
  const double omega = std::clamp(options.turn_gain_radps_per_px * shift_px,
                                  -options.max_turn_rate_radps, options.max_turn_rate_radps);
  const double speed_fraction =
      std::max(options.min_speed_fraction, 1.0 - std::abs(shift_px) / options.shift_for_stop_px);
  Twist2 twist;
  twist.v_mps = options.max_speed_mps * speed_fraction;
  twist.omega_radps = omega;
  return twist;
}

}  // namespace mapless::control

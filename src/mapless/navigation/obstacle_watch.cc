#include "mapless/navigation/obstacle_watch.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>
#include <utility>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"

namespace mapless::navigation {

namespace {

constexpr std::size_t kMaxHistory = 64;
constexpr int kSettleFrames = 3;  // frames after the stop whose view is still the reference
constexpr int kRefineRounds = 4;  // least-squares rounds after RANSAC (FitGround)

// Hartley's normalisation of a point set: centroid to the origin, mean distance sqrt(2).
cv::Matx33d Normaliser(const std::vector<cv::Point2f>& p) {
  double cx = 0.0, cy = 0.0;
  for (const auto& q : p) {
    cx += q.x;
    cy += q.y;
  }
  cx /= static_cast<double>(p.size());
  cy /= static_cast<double>(p.size());
  double d = 0.0;
  for (const auto& q : p) d += std::sqrt((q.x - cx) * (q.x - cx) + (q.y - cy) * (q.y - cy));
  d /= static_cast<double>(p.size());
  const double s = d > 1e-9 ? std::sqrt(2.0) / d : 1.0;
  return {s, 0.0, -s * cx, 0.0, s, -s * cy, 0.0, 0.0, 1.0};
}

// The homography a -> b in the least-squares (algebraic) sense: the normalised DLT. Unlike
// cv::findHomography(method 0) no Levenberg-Marquardt polish follows, which on a few hundred
// points is most of that call's cost and changes nothing here (the support is re-counted).
cv::Mat FitHomographyLsq(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b) {
  const cv::Matx33d ta = Normaliser(a), tb = Normaliser(b);
  cv::Matx<double, 9, 9> ata = cv::Matx<double, 9, 9>::zeros();
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = ta(0, 0) * a[i].x + ta(0, 2), y = ta(1, 1) * a[i].y + ta(1, 2);
    const double u = tb(0, 0) * b[i].x + tb(0, 2), v = tb(1, 1) * b[i].y + tb(1, 2);
    const double r1[9] = {x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, -u};
    const double r2[9] = {0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, -v};
    for (int j = 0; j < 9; ++j) {
      for (int k = j; k < 9; ++k) ata(j, k) += r1[j] * r1[k] + r2[j] * r2[k];
    }
  }
  for (int j = 0; j < 9; ++j) {
    for (int k = 0; k < j; ++k) ata(j, k) = ata(k, j);
  }
  cv::Mat values, vectors;
  if (!cv::eigen(cv::Mat(ata), values, vectors)) return {};
  cv::Matx33d hn;
  for (int k = 0; k < 9; ++k) hn(k / 3, k % 3) = vectors.at<double>(8, k);  // the smallest
  const cv::Matx33d h = tb.inv() * hn * ta;
  if (std::abs(h(2, 2)) < 1e-12) return {};
  return cv::Mat(h * (1.0 / h(2, 2)), true);
}

}  // namespace

void ObstacleWatchOptions::Validate() const {
  MAPLESS_CHECK(baseline_m > 0.0,
                "ObstacleWatchOptions.baseline_m = " << baseline_m << "; must be > 0");
  MAPLESS_CHECK(max_baseline_rad > 0.0,
                "ObstacleWatchOptions.max_baseline_rad = " << max_baseline_rad << "; must be > 0");
  MAPLESS_CHECK(max_age_s > 0.0,
                "ObstacleWatchOptions.max_age_s = " << max_age_s << "; must be > 0");
  MAPLESS_CHECK(region_top >= 0.0 && region_top < 1.0,
                "ObstacleWatchOptions.region_top = " << region_top << "; must be in [0, 1)");
  MAPLESS_CHECK(region_far_m > 0.0,
                "ObstacleWatchOptions.region_far_m = " << region_far_m << "; must be > 0");
  MAPLESS_CHECK(region_width > 0.0 && region_width <= 1.0,
                "ObstacleWatchOptions.region_width = " << region_width << "; must be in (0, 1]");
  MAPLESS_CHECK(region_half_width_m > 0.0, "ObstacleWatchOptions.region_half_width_m = "
                                               << region_half_width_m << "; must be > 0");
  MAPLESS_CHECK(horizon >= 0.0 && horizon < region_top,
                "ObstacleWatchOptions.horizon = " << horizon << "; must be in [0, region_top = "
                                                  << region_top << ")");
  MAPLESS_CHECK(fit_top >= 0.0 && fit_top < 1.0,
                "ObstacleWatchOptions.fit_top = " << fit_top << "; must be in [0, 1)");
  MAPLESS_CHECK(grid_px >= 2 && grid_px <= 64,
                "ObstacleWatchOptions.grid_px = " << grid_px << "; must be in [2, 64]");
  MAPLESS_CHECK(window_px >= 5 && window_px <= 63 && window_px % 2 == 1,
                "ObstacleWatchOptions.window_px = " << window_px << "; must be odd, in [5, 63]");
  MAPLESS_CHECK(levels >= 0 && levels <= 6,
                "ObstacleWatchOptions.levels = " << levels << "; must be in [0, 6]");
  MAPLESS_CHECK(max_round_trip_px > 0.0, "ObstacleWatchOptions.max_round_trip_px = "
                                             << max_round_trip_px << "; must be > 0");
  MAPLESS_CHECK(draw_top >= fit_top && draw_top < 1.0,
                "ObstacleWatchOptions.draw_top = " << draw_top << "; must be in [fit_top, 1)");
  MAPLESS_CHECK(ransac_iterations >= 1, "ObstacleWatchOptions.ransac_iterations = "
                                            << ransac_iterations << "; must be >= 1");
  MAPLESS_CHECK(min_eigen > 0.0,
                "ObstacleWatchOptions.min_eigen = " << min_eigen << "; must be > 0");
  MAPLESS_CHECK(ransac_px > 0.0,
                "ObstacleWatchOptions.ransac_px = " << ransac_px << "; must be > 0");
  MAPLESS_CHECK(tolerance_px > 0.0 && tolerance_relative >= 0.0,
                "ObstacleWatchOptions.tolerance_px = " << tolerance_px << ", tolerance_relative = "
                                                       << tolerance_relative
                                                       << "; must be > 0 and >= 0");
  MAPLESS_CHECK(known_radius_px >= 0.0,
                "ObstacleWatchOptions.known_radius_px = " << known_radius_px << "; must be >= 0");
  MAPLESS_CHECK(min_region_points >= 1, "ObstacleWatchOptions.min_region_points = "
                                            << min_region_points << "; must be >= 1");
  MAPLESS_CHECK(single_check_fraction > 0.0 && single_check_fraction <= 1.0,
                "ObstacleWatchOptions.single_check_fraction = " << single_check_fraction
                                                                << "; must be in (0, 1]");
  MAPLESS_CHECK(min_obstacle_points >= 1, "ObstacleWatchOptions.min_obstacle_points = "
                                              << min_obstacle_points << "; must be >= 1");
  MAPLESS_CHECK(min_blocked_fraction > 0.0 && min_blocked_fraction < 1.0,
                "ObstacleWatchOptions.min_blocked_fraction = " << min_blocked_fraction
                                                               << "; must be in (0, 1)");
  MAPLESS_CHECK(confirm_frames >= 1,
                "ObstacleWatchOptions.confirm_frames = " << confirm_frames << "; must be >= 1");
  MAPLESS_CHECK(max_unchecked_m >= 0.0,
                "ObstacleWatchOptions.max_unchecked_m = " << max_unchecked_m << "; must be >= 0");
  MAPLESS_CHECK(min_eigen_clean > 0.0,
                "ObstacleWatchOptions.min_eigen_clean = " << min_eigen_clean << "; must be > 0");
  MAPLESS_CHECK(noise_eigen_factor >= 0.0, "ObstacleWatchOptions.noise_eigen_factor = "
                                               << noise_eigen_factor << "; must be >= 0");
  MAPLESS_CHECK(creep_m >= 0.0, "ObstacleWatchOptions.creep_m = " << creep_m << "; must be >= 0");
  MAPLESS_CHECK(creep_m == 0.0 || creep_speed_mps > 0.0,
                "ObstacleWatchOptions.creep_speed_mps = " << creep_speed_mps << "; must be > 0");
  MAPLESS_CHECK(curvature_window_m >= 0.0 && max_curvature_per_m > 0.0,
                "ObstacleWatchOptions.curvature_window_m = "
                    << curvature_window_m << ", max_curvature_per_m = " << max_curvature_per_m
                    << "; must be >= 0 and > 0");
  MAPLESS_CHECK(hidden_drop >= 0.0 && hidden_drop < 1.0,
                "ObstacleWatchOptions.hidden_drop = " << hidden_drop << "; must be in [0, 1)");
  MAPLESS_CHECK(hidden_min_reference > 0.0 && hidden_min_reference <= 1.0,
                "ObstacleWatchOptions.hidden_min_reference = " << hidden_min_reference
                                                               << "; must be in (0, 1]");
  MAPLESS_CHECK(hidden_window_m > 0.0 && hidden_gap_m >= 0.0 && hidden_max_turn_rad > 0.0,
                "ObstacleWatchOptions.hidden_window_m = "
                    << hidden_window_m << ", hidden_gap_m = " << hidden_gap_m
                    << ", hidden_max_turn_rad = " << hidden_max_turn_rad
                    << "; must be > 0, >= 0 and > 0");
  MAPLESS_CHECK(free_difference > 0.0,
                "ObstacleWatchOptions.free_difference = " << free_difference << "; must be > 0");
}

ObstacleWatch::ObstacleWatch(ObstacleWatchOptions options) : options_(std::move(options)) {
  options_.Validate();
}

ObstacleCheck ObstacleWatch::Update(const cv::Mat& grey, Timestamp t_ns, double forward_m,
                                    double turned_rad, const std::vector<cv::Point2f>& known_px,
                                    double route_left_m) {
  MAPLESS_CHECK(!grey.empty() && grey.type() == CV_8UC1,
                "ObstacleWatch: expected a non-empty 8-bit grey image");
  ObstacleCheck check;
  if (!options_.enabled) return check;
  route_left_m_ = std::max(route_left_m, 1e-3);
  forward_m_ += std::max(0.0, forward_m);
  // The heading, not the turning's total: the standard funnel lane turns +-R every frame, and
  // the sum of |turning| ruled out every pair of frames 8 cm apart (it never looked).
  turned_rad_ += turned_rad;
  if (blocked_) {
    check = WatchBlocked(grey);
  } else {
    // The frame's pyramid with its derivatives (this frame is Lucas-Kanade's first image); kept
    // without them (when it is the earlier frame, only candidates are tracked from it).
    std::vector<cv::Mat> pyramid;
    cv::buildOpticalFlowPyramid(grey, pyramid, cv::Size(options_.window_px, options_.window_px),
                                options_.levels, true);
    curvature_ = Curvature();
    min_eigen_ = MinEigen(grey);
    check = Look(grey, pyramid, t_ns, known_px);
    if (!blocked_) Hidden(grey, pyramid, &check);
    Unchecked(grey, forward_m, &check);
    if (!blocked_) {
      Frame frame{{}, t_ns, forward_m_, turned_rad_};
      for (std::size_t l = 0; l < pyramid.size(); l += 2) frame.pyramid.push_back(pyramid[l]);
      history_.push_back(std::move(frame));
    }
  }
  if (blocked_) {
    history_.clear();  // a stopped robot: the next check needs a new baseline
  } else {
    while (history_.size() > kMaxHistory ||
           (!history_.empty() && ToSeconds(t_ns - history_.front().t_ns) > options_.max_age_s)) {
      history_.pop_front();
    }
  }
  return check;
}

void ObstacleWatch::Resume() {
  blocked_ = false;
  creeping_ = false;
  unchecked_m_ = 0.0;
  votes_ = 0;
  free_votes_ = 0;
  hidden_votes_ = 0;
  history_.clear();
  textures_.clear();
}

cv::Mat ObstacleWatch::FitGround(const std::vector<cv::Point2f>& here,
                                 const std::vector<cv::Point2f>& there,
                                 const std::vector<int>& draw) const {
  // RANSAC (the dominant plane, Section 3.4) with the hypotheses drawn from the bottom rows only
  // (the ground a robot stands on; a close obstacle has a planar flow too and may cover more of
  // the image) and their support counted on every fit point; a fixed seed, so a frame pair
  // always gives the same answer.
  Rng rng(0x0b57ac1e);
  const auto inlier = [&](const cv::Mat& h, std::size_t i) {
    const double* m = h.ptr<double>();
    const double x = here[i].x, y = here[i].y;
    const double w = m[6] * x + m[7] * y + m[8];
    if (std::abs(w) < 1e-9) return false;
    const double ex = there[i].x - (m[0] * x + m[1] * y + m[2]) / w;
    const double ey = there[i].y - (m[3] * x + m[4] * y + m[5]) / w;
    const double fx = there[i].x - x, fy = there[i].y - y;
    const double allowed =
        options_.ransac_px + options_.tolerance_relative * std::sqrt(fx * fx + fy * fy);
    return ex * ex + ey * ey <= allowed * allowed;
  };
  std::vector<char> is_draw(here.size(), 0);
  for (int i : draw) is_draw[static_cast<std::size_t>(i)] = 1;
  cv::Mat best;
  std::size_t best_count = 0;
  double needed = options_.ransac_iterations;  // adaptive: hypotheses still worth drawing
  for (int it = 0; it < options_.ransac_iterations && it < needed; ++it) {
    std::array<int, 4> pick{};
    for (int k = 0; k < 4; ++k) {
      bool fresh = false;
      while (!fresh) {
        pick[static_cast<std::size_t>(k)] = draw[rng.UniformInt(draw.size())];
        fresh = std::find(pick.begin(), pick.begin() + k, pick[static_cast<std::size_t>(k)]) ==
                pick.begin() + k;
      }
    }
    cv::Point2f src[4], dst[4];
    for (int k = 0; k < 4; ++k) {
      src[k] = here[static_cast<std::size_t>(pick[static_cast<std::size_t>(k)])];
      dst[k] = there[static_cast<std::size_t>(pick[static_cast<std::size_t>(k)])];
    }
    const cv::Mat h = cv::getPerspectiveTransform(src, dst);
    if (h.empty() || !cv::checkRange(h)) continue;
    std::size_t count = 0, count_draw = 0;
    for (std::size_t i = 0; i < here.size(); ++i) {
      if (!inlier(h, i)) continue;
      ++count;
      count_draw += static_cast<std::size_t>(is_draw[i]);
    }
    if (count > best_count) {
      best_count = count;
      best = h;
      // The chance that 4 points drawn from the bottom rows are all ground, from this
      // hypothesis's share there; stop once a better hypothesis is unlikely to be drawn.
      const double share = static_cast<double>(count_draw) / static_cast<double>(draw.size());
      const double all4 = share * share * share * share;
      if (all4 >= 1.0) {
        needed = 0.0;
      } else if (all4 > 0.0) {
        needed = std::log(1.0 - 0.999) / std::log(1.0 - all4);
      }
    }
  }
  // The plane must explain most of the bottom rows, or it is not the ground.
  std::size_t bottom = 0;
  if (!best.empty()) {
    for (int i : draw) bottom += inlier(best, static_cast<std::size_t>(i)) ? 1 : 0;
  }
  if (best.empty() || 2 * bottom < draw.size()) return {};
  // Least squares on the support, repeated while the support grows (local optimisation: a
  // hypothesis from four bottom points extrapolates to the far rows with their noise; the fit on
  // its support does not).
  std::size_t count = best_count;
  for (int round = 0; round < kRefineRounds; ++round) {
    std::vector<cv::Point2f> a, b;
    for (std::size_t i = 0; i < here.size(); ++i) {
      if (!inlier(best, i)) continue;
      a.push_back(here[i]);
      b.push_back(there[i]);
    }
    const cv::Mat refined = a.size() >= 8 ? FitHomographyLsq(a, b) : cv::Mat();
    if (refined.empty() || !cv::checkRange(refined)) break;
    std::size_t refined_count = 0;
    for (std::size_t i = 0; i < here.size(); ++i) refined_count += inlier(refined, i) ? 1 : 0;
    if (round > 0 && refined_count <= count) break;
    best = refined;
    count = refined_count;
  }
  return best;
}

const ObstacleWatch::Frame* ObstacleWatch::BaselineFrame(const cv::Size& size,
                                                         Timestamp t_ns) const {
  // The newest frame at least a baseline behind; none when the robot turned too much since.
  const Frame* earlier = nullptr;
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    if (forward_m_ - it->forward_m < options_.baseline_m) continue;
    if (std::abs(turned_rad_ - it->turned_rad) <= options_.max_baseline_rad &&
        ToSeconds(t_ns - it->t_ns) <= options_.max_age_s && it->pyramid.front().size() == size) {
      earlier = &*it;
    }
    break;
  }
  return earlier;
}

void ObstacleWatch::Vote(const cv::Mat& grey, const cv::Rect& region, int obstacle_points,
                         ObstacleCheck* check) {
  check->observed = true;
  check->blocked_fraction = static_cast<double>(obstacle_points) / check->region_points;
  votes_ = check->blocked_fraction > options_.min_blocked_fraction ? votes_ + 1 : 0;
  const bool at_once = check->blocked_fraction > options_.single_check_fraction &&
                       obstacle_points >= options_.min_obstacle_points;
  if (votes_ >= options_.confirm_frames || at_once) {
    cv::Mat mask = cv::Mat::zeros(region.size(), CV_8UC1);
    for (const cv::Point2f& p : check->obstacle_px) {
      cv::circle(mask,
                 cv::Point(static_cast<int>(p.x) - region.x, static_cast<int>(p.y) - region.y),
                 options_.grid_px, cv::Scalar(255), cv::FILLED);
    }
    const int percent = static_cast<int>(std::lround(100.0 * check->blocked_fraction));
    std::ostringstream why, waiting;
    why << "obstacle ahead: " << percent
        << "% of the ground ahead does not move like the ground: stopped";
    waiting << "obstacle ahead (" << percent
            << "% of the ground ahead): stopped, waiting for the way to be free";
    Hold(grey, mask, why.str(), waiting.str(), check);
  }
}

void ObstacleWatch::Hold(const cv::Mat& grey, cv::Mat mask, std::string why, std::string waiting,
                         ObstacleCheck* check) {
  blocked_ = true;
  blocked_image_ = grey.clone();
  blocked_mask_ = std::move(mask);
  blocked_why_ = std::move(waiting);
  check->blocked = true;
  check->reason = std::move(why);
  settle_ = 0;
  free_votes_ = 0;
}

ObstacleCheck ObstacleWatch::Look(const cv::Mat& grey, const std::vector<cv::Mat>& pyramid,
                                  Timestamp t_ns, const std::vector<cv::Point2f>& known_px) {
  ObstacleCheck check;
  const Frame* earlier = BaselineFrame(grey.size(), t_ns);
  if (earlier == nullptr) return check;  // not observable: keep the votes as they are
  const cv::Size size = grey.size();
  const cv::Rect region = Region(size);
  // A grid over the ground ahead and the region, tracked to the earlier frame; a point without
  // texture (min_eigen) or lost is dropped.
  const int g = options_.grid_px;
  const int margin = options_.window_px / 2;
  const int top = std::min(region.y, static_cast<int>(std::lround(options_.fit_top * size.height)));
  std::vector<cv::Point2f> grid;
  for (int y = top + g / 2; y < size.height - margin / 2; y += g) {
    for (int x = margin; x < size.width - margin; x += g)
      grid.emplace_back(static_cast<float>(x), static_cast<float>(y));
  }
  if (grid.size() < 8) return check;
  std::vector<cv::Point2f> moved;
  std::vector<uchar> ok;
  std::vector<float> err;
  const cv::Size window(options_.window_px, options_.window_px);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  // Each point starts where the ground model puts it (PredictGround): the robot's motion taken
  // out of the flow, so that LK only refines (a floor of regular tiles tracked from zero flow
  // locked onto the next tile; a turn moved the view further than the pyramid reaches).
  moved.reserve(grid.size());
  for (const cv::Point2f& p : grid)
    moved.push_back(
        PredictGround(p, size, forward_m_ - earlier->forward_m, turned_rad_ - earlier->turned_rad));
  cv::calcOpticalFlowPyrLK(pyramid, earlier->pyramid, grid, moved, ok, err, window, options_.levels,
                           stop, cv::OPTFLOW_USE_INITIAL_FLOW, min_eigen_);
  const double fit_row = options_.fit_top * size.height;
  const double draw_row = options_.draw_top * size.height;
  std::vector<cv::Point2f> here, there;  // the tracked points below fit_top
  std::vector<int> draw;                 // indices into here of the points RANSAC draws from
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (!ok[i] || grid[i].y < fit_row) continue;
    if (grid[i].y >= draw_row) draw.push_back(static_cast<int>(here.size()));
    here.push_back(grid[i]);
    there.push_back(moved[i]);
  }
  if (draw.size() < 8) return check;  // a plain floor: nothing to measure
  const cv::Mat h = FitGround(here, there, draw);
  if (h.empty()) {
    check.no_ground = true;
    return check;
  }
  check.plane_found = true;
  // The region's points off the plane (and not next to the taught scene) are the candidates;
  // with avoid, also every other point below fit_top off the plane (the obstacle's extent).
  std::vector<cv::Point2f> predicted;
  cv::perspectiveTransform(here, predicted, h);
  const double r2 = options_.known_radius_px * options_.known_radius_px;
  const auto known = [&](const cv::Point2f& p) {
    return std::any_of(known_px.begin(), known_px.end(), [&](const cv::Point2f& k) {
      const double dx = k.x - p.x, dy = k.y - p.y;
      return dx * dx + dy * dy <= r2;
    });
  };
  int region_points = 0;
  std::vector<cv::Point2f> candidates, candidates_there;
  std::vector<char> candidate_in_region;
  for (std::size_t i = 0; i < here.size(); ++i) {
    const bool in_region = InRegion(here[i], size);
    region_points += in_region ? 1 : 0;
    if (!in_region && !options_.avoid) continue;
    const double flow = cv::norm(there[i] - here[i]);
    const double off = cv::norm(there[i] - predicted[i]);
    if (off > options_.tolerance_px + options_.tolerance_relative * flow &&
        !(in_region && known(here[i]))) {
      candidates.push_back(here[i]);
      candidates_there.push_back(there[i]);
      candidate_in_region.push_back(in_region ? 1 : 0);
    }
  }
  if (region_points == 0) return check;
  // A candidate counts when its track is right: tracked back, it returns to where it started.
  // One that does not is a wrong track, neither obstacle nor ground: out of the count.
  int obstacle_points = 0;
  if (!candidates.empty()) {
    std::vector<uchar> ok_back;
    std::vector<cv::Point2f> back = candidates;  // back where they started, if right
    cv::calcOpticalFlowPyrLK(earlier->pyramid, pyramid, candidates_there, back, ok_back, err,
                             window, options_.levels, stop, cv::OPTFLOW_USE_INITIAL_FLOW,
                             min_eigen_);
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const bool right =
          ok_back[c] && cv::norm(back[c] - candidates[c]) <= options_.max_round_trip_px;
      if (right) check.off_plane_px.push_back(candidates[c]);
      if (!candidate_in_region[c]) continue;
      if (right) {
        ++obstacle_points;
        check.obstacle_px.push_back(candidates[c]);
      } else {
        --region_points;
      }
    }
  }
  check.region_points = region_points;
  check.curvature_per_m = curvature_;
  check.min_eigen = min_eigen_;
  if (check.region_points < options_.min_region_points &&
      obstacle_points < options_.min_obstacle_points)
    return check;
  Vote(grey, region, obstacle_points, &check);
  return check;
}

ObstacleCheck ObstacleWatch::WatchBlocked(const cv::Mat& grey) {
  ObstacleCheck check;
  check.blocked = true;
  const cv::Rect region = Region(grey.size());
  if (grey.size() != blocked_image_.size()) {
    blocked_image_ = grey.clone();
    settle_ = 0;
  }
  cv::Mat a, b, diff;
  cv::GaussianBlur(grey(region), a, cv::Size(5, 5), 0);
  if (settle_ < kSettleFrames) {
    // The robot is still coming to a halt: its view is the reference.
    ++settle_;
    blocked_image_ = grey.clone();
    check.reason = blocked_why_;
    return check;
  }
  cv::GaussianBlur(blocked_image_(region), b, cv::Size(5, 5), 0);
  cv::absdiff(a, b, diff);
  const double change = cv::mean(diff, blocked_mask_)[0];
  free_votes_ = change > options_.free_difference ? free_votes_ + 1 : 0;
  if (free_votes_ >= options_.confirm_frames) {
    blocked_ = false;
    votes_ = 0;
    unchecked_m_ = 0.0;
    check.blocked = false;
    check.cleared = true;
    return check;
  }
  check.reason = blocked_why_;
  return check;
}

}  // namespace mapless::navigation

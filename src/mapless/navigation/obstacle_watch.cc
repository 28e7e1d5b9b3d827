#include "mapless/navigation/obstacle_watch.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"

namespace mapless::navigation {
namespace {

constexpr std::size_t kMaxHistory = 64;
constexpr int kSettleFrames = 3;  // frames after the stop whose view is still the reference

}  // namespace

void ObstacleWatchOptions::Validate() const {
  MAPLESS_CHECK(baseline_m > 0.0,
                "ObstacleWatchOptions.baseline_m = " << baseline_m << "; must be > 0");
  MAPLESS_CHECK(max_baseline_rad > 0.0, "ObstacleWatchOptions.max_baseline_rad = "
                                            << max_baseline_rad << "; must be > 0");
  MAPLESS_CHECK(max_age_s > 0.0,
                "ObstacleWatchOptions.max_age_s = " << max_age_s << "; must be > 0");
  MAPLESS_CHECK(region_top >= 0.0 && region_top < 1.0,
                "ObstacleWatchOptions.region_top = " << region_top << "; must be in [0, 1)");
  MAPLESS_CHECK(region_width > 0.0 && region_width <= 1.0,
                "ObstacleWatchOptions.region_width = " << region_width << "; must be in (0, 1]");
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
  MAPLESS_CHECK(draw_top >= fit_top && draw_top < 1.0, "ObstacleWatchOptions.draw_top = "
                                                         << draw_top
                                                         << "; must be in [fit_top, 1)");
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
  MAPLESS_CHECK(known_radius_px >= 0.0, "ObstacleWatchOptions.known_radius_px = "
                                           << known_radius_px << "; must be >= 0");
  MAPLESS_CHECK(min_region_points >= 1, "ObstacleWatchOptions.min_region_points = "
                                            << min_region_points << "; must be >= 1");
  MAPLESS_CHECK(min_blocked_fraction > 0.0 && min_blocked_fraction < 1.0,
                "ObstacleWatchOptions.min_blocked_fraction = " << min_blocked_fraction
                                                               << "; must be in (0, 1)");
  MAPLESS_CHECK(confirm_frames >= 1,
                "ObstacleWatchOptions.confirm_frames = " << confirm_frames << "; must be >= 1");
  MAPLESS_CHECK(free_difference > 0.0, "ObstacleWatchOptions.free_difference = "
                                           << free_difference << "; must be > 0");
}

ObstacleWatch::ObstacleWatch(ObstacleWatchOptions options) : options_(std::move(options)) {
  options_.Validate();
}

cv::Rect ObstacleWatch::Region(cv::Size size) const {
  const int top = std::clamp(static_cast<int>(std::lround(options_.region_top * size.height)), 0,
                             size.height - 1);
  const int w = std::clamp(static_cast<int>(std::lround(options_.region_width * size.width)), 1,
                           size.width);
  return {(size.width - w) / 2, top, w, size.height - top};
}

ObstacleCheck ObstacleWatch::Update(const cv::Mat& grey, Timestamp t_ns, double forward_m,
                                    double turned_rad, const std::vector<cv::Point2f>& known_px) {
  MAPLESS_CHECK(!grey.empty() && grey.type() == CV_8UC1,
                "ObstacleWatch: expected a non-empty 8-bit grey image");
  ObstacleCheck check;
  if (!options_.enabled) return check;
  forward_m_ += std::max(0.0, forward_m);
  turned_rad_ += std::abs(turned_rad);
  check = blocked_ ? WatchBlocked(grey) : Look(grey, t_ns, known_px);
  if (blocked_) {
    history_.clear();  // a stopped robot: the next check needs a new baseline
  } else {
    history_.push_back({grey.clone(), t_ns, forward_m_, turned_rad_});
    while (history_.size() > kMaxHistory ||
           (!history_.empty() &&
            ToSeconds(t_ns - history_.front().t_ns) > options_.max_age_s)) {
      history_.pop_front();
    }
  }
  return check;
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
    const double px = (m[0] * x + m[1] * y + m[2]) / w, py = (m[3] * x + m[4] * y + m[5]) / w;
    const double flow = std::hypot(there[i].x - x, there[i].y - y);
    return std::hypot(there[i].x - px, there[i].y - py) <=
           options_.ransac_px + options_.tolerance_relative * flow;
  };
  cv::Mat best;
  std::size_t best_count = 0;
  for (int it = 0; it < options_.ransac_iterations; ++it) {
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
    std::size_t count = 0;
    for (std::size_t i = 0; i < here.size(); ++i) count += inlier(h, i) ? 1 : 0;
    if (count > best_count) {
      best_count = count;
      best = h;
    }
  }
  // The plane must explain most of the bottom rows, or it is not the ground.
  std::size_t bottom = 0;
  if (!best.empty()) {
    for (int i : draw) bottom += inlier(best, static_cast<std::size_t>(i)) ? 1 : 0;
  }
  if (best.empty() || 2 * bottom < draw.size()) return {};
  // Least squares on the support.
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < here.size(); ++i) {
    if (!inlier(best, i)) continue;
    a.push_back(here[i]);
    b.push_back(there[i]);
  }
  const cv::Mat refined = a.size() >= 8 ? cv::findHomography(a, b, 0) : cv::Mat();
  return refined.empty() ? best : refined;
}

ObstacleCheck ObstacleWatch::Look(const cv::Mat& grey, Timestamp t_ns,
                                  const std::vector<cv::Point2f>& known_px) {
  ObstacleCheck check;
  // The newest frame at least a baseline behind; none when the robot turned too much since.
  const Frame* earlier = nullptr;
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    if (forward_m_ - it->forward_m < options_.baseline_m) continue;
    if (turned_rad_ - it->turned_rad <= options_.max_baseline_rad &&
        ToSeconds(t_ns - it->t_ns) <= options_.max_age_s && it->image.size() == grey.size()) {
      earlier = &*it;
    }
    break;
  }
  if (earlier == nullptr) return check;  // not observable: keep the votes as they are
  const cv::Size size = grey.size();
  const cv::Rect region = Region(size);
  // A grid over the ground ahead and the region, tracked back to the earlier frame and forward
  // again; a point whose round trip does not close is dropped (no texture, an occlusion).
  const int g = options_.grid_px;
  const int margin = options_.window_px / 2;
  const int top = std::min(region.y, static_cast<int>(std::lround(options_.fit_top * size.height)));
  std::vector<cv::Point2f> here;
  for (int y = top + g / 2; y < size.height - margin / 2; y += g) {
    for (int x = margin; x < size.width - margin; x += g)
      here.emplace_back(static_cast<float>(x), static_cast<float>(y));
  }
  if (here.size() < 8) return check;
  std::vector<cv::Point2f> there, back;
  std::vector<uchar> ok, ok_back;
  std::vector<float> err;
  const cv::Size window(options_.window_px, options_.window_px);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  const double min_eigen = options_.min_eigen;
  cv::calcOpticalFlowPyrLK(grey, earlier->image, here, there, ok, err, window, options_.levels,
                           stop, 0, min_eigen);
  cv::calcOpticalFlowPyrLK(earlier->image, grey, there, back, ok_back, err, window,
                           options_.levels, stop, 0, min_eigen);
  const double fit_row = options_.fit_top * size.height;
  const double draw_row = options_.draw_top * size.height;
  std::vector<cv::Point2f> fit_here, fit_there;
  std::vector<std::size_t> kept;
  std::vector<int> draw;  // indices into fit_here of the points hypotheses are drawn from
  for (std::size_t i = 0; i < here.size(); ++i) {
    if (!ok[i] || !ok_back[i]) continue;
    if (cv::norm(back[i] - here[i]) > options_.max_round_trip_px) continue;
    kept.push_back(i);
    if (here[i].y >= fit_row) {
      if (here[i].y >= draw_row) draw.push_back(static_cast<int>(fit_here.size()));
      fit_here.push_back(here[i]);
      fit_there.push_back(there[i]);
    }
  }
  if (draw.size() < 8) return check;  // a plain floor: nothing to measure
  const cv::Mat h = FitGround(fit_here, fit_there, draw);
  if (h.empty()) return check;
  check.plane_found = true;
  std::vector<cv::Point2f> in_region, predicted;
  for (std::size_t i : kept) {
    if (region.contains(cv::Point(static_cast<int>(here[i].x), static_cast<int>(here[i].y))))
      in_region.push_back(here[i]);
  }
  check.region_points = static_cast<int>(in_region.size());
  if (!check.plane_found || check.region_points < options_.min_region_points) return check;
  check.observed = true;
  cv::perspectiveTransform(in_region, predicted, h);
  int obstacle_points = 0;
  std::size_t r = 0;
  for (std::size_t i : kept) {
    if (r >= in_region.size() || here[i] != in_region[r]) continue;
    const double flow = cv::norm(there[i] - here[i]);
    const double off = cv::norm(there[i] - predicted[r]);
    ++r;
    const auto known = [&](const cv::Point2f& p) {
      const double r2 = options_.known_radius_px * options_.known_radius_px;
      return std::any_of(known_px.begin(), known_px.end(), [&](const cv::Point2f& k) {
        const double dx = k.x - p.x, dy = k.y - p.y;
        return dx * dx + dy * dy <= r2;
      });
    };
    if (off > options_.tolerance_px + options_.tolerance_relative * flow && !known(here[i])) {
      ++obstacle_points;
      check.obstacle_px.push_back(here[i]);
    }
  }
  check.blocked_fraction = static_cast<double>(obstacle_points) / check.region_points;
  votes_ = check.blocked_fraction > options_.min_blocked_fraction ? votes_ + 1 : 0;
  if (votes_ >= options_.confirm_frames) {
    blocked_ = true;
    blocked_at_fraction_ = check.blocked_fraction;
    blocked_image_ = grey.clone();
    blocked_mask_ = cv::Mat::zeros(region.size(), CV_8UC1);
    for (const cv::Point2f& p : check.obstacle_px) {
      cv::circle(blocked_mask_, cv::Point(static_cast<int>(p.x) - region.x,
                                          static_cast<int>(p.y) - region.y),
                 options_.grid_px, cv::Scalar(255), cv::FILLED);
    }
    check.blocked = true;
    std::ostringstream why;
    why << "obstacle ahead: " << static_cast<int>(std::lround(100.0 * check.blocked_fraction))
        << "% of the ground ahead does not move like the ground: stopped";
    check.reason = why.str();
    settle_ = 0;
    free_votes_ = 0;
  }
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
    check.reason = "obstacle ahead: stopped";
    return check;
  }
  cv::GaussianBlur(blocked_image_(region), b, cv::Size(5, 5), 0);
  cv::absdiff(a, b, diff);
  const double change = cv::mean(diff, blocked_mask_)[0];
  free_votes_ = change > options_.free_difference ? free_votes_ + 1 : 0;
  if (free_votes_ >= options_.confirm_frames) {
    blocked_ = false;
    votes_ = 0;
    check.blocked = false;
    check.cleared = true;
    return check;
  }
  std::ostringstream why;
  why << "obstacle ahead (" << static_cast<int>(std::lround(100.0 * blocked_at_fraction_))
      << "% of the ground ahead): stopped, waiting for the way to be free";
  check.reason = why.str();
  return check;
}

}  // namespace mapless::navigation

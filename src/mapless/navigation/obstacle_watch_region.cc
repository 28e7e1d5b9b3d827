// The obstacle watch's view of the frame (obstacle_watch.h): how the region bends with the path
// the robot drives, how much texture a tracked point needs given the frame's noise, where the
// ground's points should have come from, and what it does when the ground went unchecked.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "mapless/navigation/obstacle_watch.h"

namespace mapless::navigation {

cv::Rect ObstacleWatch::Region(cv::Size size) const {
  const int top = std::clamp(static_cast<int>(std::lround(options_.region_top * size.height)), 0,
                             size.height - 1);
  const int w =
      std::clamp(static_cast<int>(std::lround(options_.region_width * size.width)), 1, size.width);
  return {(size.width - w) / 2, top, w, size.height - top};
}

bool ObstacleWatch::InRegion(cv::Point2f p, cv::Size size) const {
  return std::abs(StripOffset(p, size)) <= 1.0;
}

double ObstacleWatch::StripOffset(cv::Point2f p, cv::Size size) const {
  constexpr double kOut = std::numeric_limits<double>::infinity();
  if (p.y < options_.region_top * size.height) return kOut;
  const double horizon = options_.horizon * size.height;
  // Ground farther than the route goes: rows above the one at route_left_m_.
  if (p.y < horizon + (options_.region_top * size.height - horizon) * options_.region_far_m /
                          route_left_m_)
    return kOut;
  const double below = p.y - horizon;
  const double half = 0.5 * options_.region_width * size.width * below / (size.height - horizon);
  // The strip bends with the path: at distance d ahead it is curvature * d^2 / 2 to the side
  // (metres), half / region_half_width_m pixels a metre on this row.
  const double d = options_.region_far_m * (options_.region_top * size.height - horizon) / below;
  const double centre =
      0.5 * size.width - curvature_ * 0.5 * d * d * half / options_.region_half_width_m;
  return (p.x - centre) / half;
}

double ObstacleWatch::Curvature() const {
  if (options_.curvature_window_m <= 0.0 || history_.empty()) return 0.0;
  // The newest frame at least the window behind, else the oldest kept (at least 5 cm behind).
  const Frame* from = nullptr;
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    from = &*it;
    if (forward_m_ - it->forward_m >= options_.curvature_window_m) break;
  }
  const double driven = forward_m_ - from->forward_m;
  if (driven < 0.05) return 0.0;
  const double k = (turned_rad_ - from->turned_rad) / driven;
  return std::clamp(k, -options_.max_curvature_per_m, options_.max_curvature_per_m);
}

cv::Point2f ObstacleWatch::PredictGround(cv::Point2f p, cv::Size size, double forward_m,
                                         double turned_rad) const {
  const double horizon = options_.horizon * size.height;
  const double fh = options_.region_far_m * (options_.region_top * size.height - horizon);
  const double f = 0.5 * options_.region_width * size.width / options_.region_half_width_m * fh /
                   (size.height - horizon);
  const double cx = 0.5 * (size.width - 1);
  const double below = p.y - horizon;
  if (below < 1.0 || fh <= 0.0) return p;
  // The ground point in the current robot frame (forward d, left), then in the earlier one: the
  // robot turned by turned_rad while it drove forward_m along the chord of its arc.
  const double d = fh / below;
  const double left = -(p.x - cx) * d / f;
  const double c = std::cos(turned_rad), s = std::sin(turned_rad);
  const double forward = c * d - s * left + forward_m * std::cos(0.5 * turned_rad);
  const double side = s * d + c * left + forward_m * std::sin(0.5 * turned_rad);
  if (forward < 0.05) return p;
  return {static_cast<float>(cx - f * side / forward), static_cast<float>(horizon + fh / forward)};
}

double ObstacleWatch::MinEigen(const cv::Mat& grey) const {
  if (options_.noise_eigen_factor <= 0.0) return options_.min_eigen;
  // Immerkaer (1996): the image filtered with the difference of two Laplacians has, on Gaussian
  // noise of sigma grey levels, a standard deviation of 6 sigma; texture adds to it only where
  // it is fine, so the median over the lower image (every other row and column) measures the
  // noise (a textured frame reads high, and keeps min_eigen).
  const int top = static_cast<int>(std::lround(options_.fit_top * grey.rows));
  const cv::Mat lower = grey.rowRange(std::clamp(top, 0, grey.rows - 3), grey.rows);
  cv::Mat response;
  const cv::Mat kernel = (cv::Mat_<short>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::filter2D(lower, response, CV_16S, kernel, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  std::array<int, 4096> histogram{};
  int count = 0;
  for (int y = 1; y + 1 < response.rows; y += 2) {
    const short* row = response.ptr<short>(y);
    for (int x = 1; x + 1 < response.cols; x += 2) {
      ++histogram[static_cast<std::size_t>(std::min(std::abs(static_cast<int>(row[x])), 4095))];
      ++count;
    }
  }
  int median = 0;
  int seen = 0;
  while (median < 4095 && seen + histogram[static_cast<std::size_t>(median)] <= count / 2) {
    seen += histogram[static_cast<std::size_t>(median)];
    ++median;
  }
  const double sigma = median / (0.6745 * 6.0);
  constexpr double kNoiseEigenPerSigma2 = 1.87e-4;  // the median window's (see the options)
  return std::clamp(options_.noise_eigen_factor * kNoiseEigenPerSigma2 * sigma * sigma,
                    std::min(options_.min_eigen_clean, options_.min_eigen), options_.min_eigen);
}

void ObstacleWatch::Unchecked(const cv::Mat& grey, double forward_m, ObstacleCheck* check) {
  unchecked_m_ = check->observed ? 0.0 : unchecked_m_ + std::max(0.0, forward_m);
  check->unchecked_m = unchecked_m_;
  if (creeping_) {
    crept_m_ += std::max(0.0, forward_m);
    if (check->observed || blocked_) {
      creeping_ = false;  // the check had its say
    } else if (crept_m_ > options_.creep_m) {
      creeping_ = false;
      StopUnchecked(grey, check);
    }
  } else if (!blocked_ && options_.max_unchecked_m > 0.0 &&
             unchecked_m_ > options_.max_unchecked_m) {
    if (options_.creep_m > 0.0) {
      creeping_ = true;
      crept_m_ = 0.0;
    } else {
      StopUnchecked(grey, check);
    }
  }
  if (creeping_) {
    std::ostringstream why;
    why.precision(2);
    why << std::fixed << "the ground ahead was not checked over the last " << unchecked_m_
        << " m: creeping straight ahead to check it (" << crept_m_ << " of " << options_.creep_m
        << " m)";
    check->creeping = true;
    check->reason = why.str();
  }
}

void ObstacleWatch::StopUnchecked(const cv::Mat& grey, ObstacleCheck* check) {
  std::ostringstream why;
  why.precision(2);
  why << std::fixed << "the ground ahead was not checked over the last " << unchecked_m_ << " m ("
      << check->region_points << " points tracked there, " << options_.min_region_points
      << " needed"
      << (options_.creep_m > 0.0 ? ", also creeping straight ahead" : ", or the robot turned")
      << "): stopped";
  // The whole region: the view changing there frees it.
  Hold(grey, cv::Mat(Region(grey.size()).size(), CV_8UC1, cv::Scalar(255)), why.str(),
       "the ground ahead could not be checked: stopped, waiting for the view to change", check);
}

}  // namespace mapless::navigation

// The obstacle watch's hidden-ground check (ObstacleWatchOptions::hidden_drop): the strip's thirds
// losing the texture they had. The flow check (obstacle_watch.cc) sees what moves unlike the
// ground; a face without texture gives it no points at all, while it hides the textured ground
// behind it. This check sees that.
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>
#include <vector>

#include "mapless/navigation/obstacle_watch.h"

namespace mapless::navigation {

namespace {

constexpr std::size_t kMaxTextures = 400;
constexpr int kMinThirdPoints = 6;  // fewer grid points in a third: no share measured
const char* const kThirdName[3] = {"left", "middle", "right"};

// The share a third keeps on all but its worst fifth of frames: a floor whose texture comes and
// goes (patches of plain ground) has a low one and is not judged.
double LowShare(std::vector<double> v) {
  const std::size_t k = v.size() / 5;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

}  // namespace

void ObstacleWatch::Hidden(const cv::Mat& grey, const std::vector<cv::Mat>& pyramid,
                           ObstacleCheck* check) {
  if (options_.hidden_drop <= 0.0) return;
  const cv::Size size = grey.size();
  const cv::Rect region = Region(size);
  // The region's grid points, each in its third; textured when Lucas-Kanade would track it
  // (min_eigen_, the flow check's threshold): a point tracked onto its own image.
  const int g = options_.grid_px;
  const int margin = options_.window_px / 2;
  std::vector<cv::Point2f> points;
  std::vector<int> third;
  for (int y = region.y + g / 2; y < size.height - margin / 2; y += g) {
    for (int x = margin; x < size.width - margin; x += g) {
      const cv::Point2f p(static_cast<float>(x), static_cast<float>(y));
      const double u = StripOffset(p, size);
      if (std::abs(u) > 1.0) continue;
      points.push_back(p);
      third.push_back(u < -1.0 / 3.0 ? 0 : (u > 1.0 / 3.0 ? 2 : 1));
    }
  }
  Texture texture{forward_m_, turned_rad_, {-1.0, -1.0, -1.0}};
  std::vector<uchar> ok;
  if (!points.empty()) {
    std::vector<cv::Point2f> same = points;
    std::vector<float> err;
    cv::calcOpticalFlowPyrLK(pyramid, pyramid, points, same, ok, err,
                             cv::Size(options_.window_px, options_.window_px), 0,
                             cv::TermCriteria(cv::TermCriteria::COUNT, 1, 0.0),
                             cv::OPTFLOW_USE_INITIAL_FLOW, min_eigen_);
    std::array<int, 3> n{}, textured{};
    for (std::size_t i = 0; i < points.size(); ++i) {
      ++n[static_cast<std::size_t>(third[i])];
      textured[static_cast<std::size_t>(third[i])] += ok[i] ? 1 : 0;
    }
    for (std::size_t t = 0; t < 3; ++t) {
      if (n[t] >= kMinThirdPoints) texture.share[t] = static_cast<double>(textured[t]) / n[t];
    }
  }
  check->textured = texture.share;
  // The reference: each third's median over the frames between hidden_gap_m and hidden_gap_m +
  // hidden_window_m of driving back, seen with about today's heading.
  std::array<std::vector<double>, 3> before;
  for (const Texture& old : textures_) {
    const double back = forward_m_ - old.forward_m;
    if (back < options_.hidden_gap_m || back > options_.hidden_gap_m + options_.hidden_window_m ||
        std::abs(turned_rad_ - old.turned_rad) > options_.hidden_max_turn_rad)
      continue;
    for (std::size_t t = 0; t < 3; ++t) {
      if (old.share[t] >= 0.0) before[t].push_back(old.share[t]);
    }
  }
  // Judged only with the whole strip in view: bent far by a sharp turn, what is left of it at the
  // image's edge is not the ground the robot will drive over.
  const bool whole = std::all_of(texture.share.begin(), texture.share.end(),
                                 [](double share) { return share >= 0.0; });
  int hidden = -1;
  for (std::size_t t = 0; t < 3 && whole; ++t) {
    if (before[t].size() < 5) continue;
    check->textured_before[t] = LowShare(before[t]);
    if (texture.share[t] >= 0.0 && check->textured_before[t] >= options_.hidden_min_reference &&
        texture.share[t] < options_.hidden_drop * check->textured_before[t] && hidden < 0)
      hidden = static_cast<int>(t);
  }
  textures_.push_back(texture);
  while (textures_.size() > kMaxTextures ||
         forward_m_ - textures_.front().forward_m >
             options_.hidden_gap_m + options_.hidden_window_m + 0.1)
    textures_.pop_front();
  hidden_votes_ = hidden >= 0 ? hidden_votes_ + 1 : 0;
  if (hidden_votes_ < options_.confirm_frames) return;
  hidden_votes_ = 0;
  // Stop; the hidden third's points are where the view must change to go on.
  cv::Mat mask = cv::Mat::zeros(region.size(), CV_8UC1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (third[i] != hidden) continue;
    cv::circle(mask,
               cv::Point(static_cast<int>(points[i].x) - region.x,
                         static_cast<int>(points[i].y) - region.y),
               g, cv::Scalar(255), cv::FILLED);
  }
  const auto t = static_cast<std::size_t>(hidden);
  std::ostringstream why;
  why << "obstacle ahead: the " << kThirdName[t] << " of the ground ahead is hidden ("
      << std::lround(100.0 * texture.share[t]) << "% of it textured, "
      << std::lround(100.0 * check->textured_before[t]) << "% before): stopped";
  Hold(grey, mask, why.str(),
       std::string("something hides the ") + kThirdName[t] +
           " of the ground ahead: stopped, waiting for the way to be free",
       check);
}

}  // namespace mapless::navigation

#include "mapless/features/klt.h"

#include <opencv2/video/tracking.hpp>

#include "mapless/core/check.h"

namespace mapless::features {

void KltOptions::Validate() const {
  MAPLESS_CHECK(window_px >= 5 && window_px <= 101 && window_px % 2 == 1,
                "KltOptions.window_px = " << window_px << "; must be odd and in [5, 101]");
  MAPLESS_CHECK(pyramid_levels >= 0 && pyramid_levels <= 8,
                "KltOptions.pyramid_levels = " << pyramid_levels << "; must be in [0, 8]");
  MAPLESS_CHECK(max_forward_backward_px > 0.0, "KltOptions.max_forward_backward_px = "
                                                   << max_forward_backward_px << "; must be > 0");
}

KltResult TrackKlt(const cv::Mat& previous, const cv::Mat& current,
                   const std::vector<cv::Point2f>& points, const KltOptions& options) {
  KltResult result;
  result.points = points;
  result.ok.assign(points.size(), false);
  if (points.empty()) return result;
  MAPLESS_CHECK(!previous.empty() && !current.empty() && previous.size() == current.size(),
                "TrackKlt: images must be non-empty and of the same size");
  const cv::Size window(options.window_px, options.window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options.max_iterations, options.epsilon);
  std::vector<cv::Point2f> forward;
  std::vector<cv::Point2f> backward;
  std::vector<uchar> status_f;
  std::vector<uchar> status_b;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(previous, current, points, forward, status_f, err, window,
                           options.pyramid_levels, criteria);
  cv::calcOpticalFlowPyrLK(current, previous, forward, backward, status_b, err, window,
                           options.pyramid_levels, criteria);
  const float w = static_cast<float>(current.cols);
  const float h = static_cast<float>(current.rows);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const cv::Point2f& p = forward[i];
    const bool inside = p.x >= 0.0f && p.y >= 0.0f && p.x <= w - 1.0f && p.y <= h - 1.0f;
    const double fb = cv::norm(backward[i] - points[i]);
    if (status_f[i] && status_b[i] && inside && fb <= options.max_forward_backward_px) {
      result.points[i] = p;
      result.ok[i] = true;
      ++result.tracked;
    }
  }
  return result;
}

}  // namespace mapless::features

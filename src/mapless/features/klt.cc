#include "mapless/features/klt.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "mapless/core/check.h"

namespace mapless::features {

int KltOptions::LevelWindowPx() const {
  const int side = window_px >> finest_level;
  return side % 2 == 1 ? side : side + 1;
}

void KltOptions::Validate() const {
  MAPLESS_CHECK(window_px >= 5 && window_px <= 101 && window_px % 2 == 1,
                "KltOptions.window_px = " << window_px << "; must be odd and in [5, 101]");
  MAPLESS_CHECK(pyramid_levels >= 0 && pyramid_levels <= 8,
                "KltOptions.pyramid_levels = " << pyramid_levels << "; must be in [0, 8]");
  MAPLESS_CHECK(finest_level >= 0 && finest_level <= pyramid_levels,
                "KltOptions.finest_level = " << finest_level << "; must be in [0, pyramid_levels = "
                                             << pyramid_levels << "]");
  MAPLESS_CHECK(LevelWindowPx() >= 5,
                "KltOptions.window_px = " << window_px << " is " << LevelWindowPx()
                                          << " px at finest_level " << finest_level
                                          << "; must be >= 5 there");
  MAPLESS_CHECK(max_forward_backward_px > 0.0, "KltOptions.max_forward_backward_px = "
                                                   << max_forward_backward_px << "; must be > 0");
}

KltPyramid BuildKltPyramid(const cv::Mat& grey, const KltOptions& options) {
  MAPLESS_CHECK(!grey.empty() && grey.type() == CV_8UC1, "BuildKltPyramid: needs a grey image");
  KltPyramid pyramid;
  pyramid.image_size = grey.size();
  cv::Mat base = grey;
  for (int l = 0; l < options.finest_level; ++l) {
    cv::Mat down;
    cv::pyrDown(base, down);
    base = down;
  }
  const int side = options.LevelWindowPx();
  pyramid.max_level = cv::buildOpticalFlowPyramid(
      base, pyramid.levels, cv::Size(side, side), options.pyramid_levels - options.finest_level,
      true, cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT, false);
  return pyramid;
}

KltResult TrackKlt(const KltPyramid& previous, const KltPyramid& current,
                   const std::vector<cv::Point2f>& points, const KltOptions& options) {
  KltResult result;
  result.points = points;
  result.ok.assign(points.size(), false);
  if (points.empty()) return result;
  MAPLESS_CHECK(!previous.empty() && !current.empty() && previous.image_size == current.image_size,
                "TrackKlt: images must be non-empty and of the same size");
  const int side = options.LevelWindowPx();
  const cv::Size window(side, side);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options.max_iterations, options.epsilon);
  const float scale = 1.0f / static_cast<float>(1 << options.finest_level);
  std::vector<cv::Point2f> start(points);
  for (cv::Point2f& p : start) p *= scale;
  std::vector<cv::Point2f> forward;
  std::vector<cv::Point2f> backward;
  std::vector<uchar> status_f;
  std::vector<uchar> status_b;
  std::vector<float> err;
  const int max_level = std::min(previous.max_level, current.max_level);
  cv::calcOpticalFlowPyrLK(previous.levels, current.levels, start, forward, status_f, err, window,
                           max_level, criteria);
  cv::calcOpticalFlowPyrLK(current.levels, previous.levels, forward, backward, status_b, err,
                           window, max_level, criteria);
  const float w = static_cast<float>(current.image_size.width);
  const float h = static_cast<float>(current.image_size.height);
  const double max_fb = options.max_forward_backward_px * scale;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const cv::Point2f p = forward[i] / scale;
    const bool inside = p.x >= 0.0f && p.y >= 0.0f && p.x <= w - 1.0f && p.y <= h - 1.0f;
    const double fb = cv::norm(backward[i] - start[i]);
    if (status_f[i] && status_b[i] && inside && fb <= max_fb) {
      result.points[i] = p;
      result.ok[i] = true;
      ++result.tracked;
    }
  }
  return result;
}

KltResult TrackKlt(const cv::Mat& previous, const cv::Mat& current,
                   const std::vector<cv::Point2f>& points, const KltOptions& options) {
  if (points.empty()) return TrackKlt(KltPyramid{}, KltPyramid{}, points, options);
  MAPLESS_CHECK(!previous.empty() && !current.empty() && previous.size() == current.size(),
                "TrackKlt: images must be non-empty and of the same size");
  return TrackKlt(BuildKltPyramid(previous, options), BuildKltPyramid(current, options), points,
                  options);
}

}  // namespace mapless::features

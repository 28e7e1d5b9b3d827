#include "mapless/navigation/teach.h"

#include <algorithm>
#include <numeric>
#include <opencv2/imgproc.hpp>

#include "mapless/control/funnel_lane.h"
#include "mapless/core/check.h"

namespace mapless::navigation {

void TeachOptions::Validate() const {
  MAPLESS_CHECK(threads == 1 || threads == 2,
                "TeachOptions.threads = " << threads << "; must be 1 or 2");
  features.Validate();
  klt.Validate();
  MAPLESS_CHECK(keyframe_tracked_fraction > 0.0 && keyframe_tracked_fraction < 1.0,
                "TeachOptions.keyframe_tracked_fraction = " << keyframe_tracked_fraction
                                                            << "; must be in (0, 1)");
  MAPLESS_CHECK(max_spread_growth == 0.0 || max_spread_growth > 1.0,
                "TeachOptions.max_spread_growth = " << max_spread_growth << "; must be 0 or > 1");
  MAPLESS_CHECK(min_keyframe_features >= 0, "TeachOptions.min_keyframe_features = "
                                                << min_keyframe_features << "; must be >= 0");
  MAPLESS_CHECK(max_tracked_features >= 0,
                "TeachOptions.max_tracked_features = " << max_tracked_features << "; must be >= 0");
  MAPLESS_CHECK(thumbnail_width_px >= 16,
                "TeachOptions.thumbnail_width_px = " << thumbnail_width_px << "; must be >= 16");
}

TeachSession::TeachSession(TeachOptions options)
    : options_(options), extractor_((options.Validate(), options.features)) {}

double TeachSession::tracked_fraction() const {
  return initial_count_ == 0
             ? 0.0
             : static_cast<double>(current_.size()) / static_cast<double>(initial_count_);
}

std::optional<route::Keyframe> TeachSession::MakeKeyframe(const cv::Mat& grey, Timestamp t_ns,
                                                          const std::optional<Pose2>& odometry) {
  // A keyframe without enough features could not be matched in the repeat: the keyframe is
  // deferred to the next frame that has them, and the deferral counted.
  const features::Features f = extractor_.Extract(grey);
  if (static_cast<int>(f.keypoints.size()) < options_.min_keyframe_features) {
    ++deferred_;
    return std::nullopt;
  }
  route::Keyframe kf;
  kf.index = next_index_++;
  kf.t_ns = t_ns;
  kf.odometry = odometry;
  const double scale = static_cast<double>(options_.thumbnail_width_px) / grey.cols;
  cv::resize(grey, kf.thumbnail, cv::Size(), scale, scale, cv::INTER_AREA);
  kf.keypoints = f.keypoints;
  kf.descriptors = f.descriptors;
  kf.segment_start_px = start_;
  kf.segment_end_px = current_;
  // The next segment tracks this keyframe's features (the strongest, up to the limit).
  std::vector<std::size_t> order(kf.keypoints.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const std::size_t limit = options_.max_tracked_features > 0
                                ? static_cast<std::size_t>(options_.max_tracked_features)
                                : order.size();
  if (order.size() > limit) {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return kf.keypoints[a].response > kf.keypoints[b].response;
    });
    order.resize(limit);
    std::sort(order.begin(), order.end());  // in the keyframe's order
  }
  start_.clear();
  for (const std::size_t i : order) start_.push_back(kf.keypoints[i].pt);
  current_ = start_;
  initial_count_ = start_.size();
  return kf;
}

features::KltResult TeachSession::Track(const features::KltPyramid& pyramid) {
  if (options_.threads < 2 || current_.size() < 2)
    return features::TrackKlt(previous_pyramid_, pyramid, current_, options_.klt);
  const auto half = static_cast<std::ptrdiff_t>(current_.size() / 2);
  const std::vector<cv::Point2f> first(current_.begin(), current_.begin() + half);
  const std::vector<cv::Point2f> second(current_.begin() + half, current_.end());
  if (!tracker_) tracker_ = std::make_unique<Worker>();
  features::KltResult a;
  tracker_->Start([&] { a = features::TrackKlt(previous_pyramid_, pyramid, first, options_.klt); });
  features::KltResult b;
  try {
    b = features::TrackKlt(previous_pyramid_, pyramid, second, options_.klt);
  } catch (...) {
    tracker_->Wait();  // it reads the pyramids: it ends before they go
    throw;
  }
  tracker_->Wait();
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  a.ok.insert(a.ok.end(), b.ok.begin(), b.ok.end());
  a.tracked += b.tracked;
  return a;
}

std::optional<route::Keyframe> TeachSession::Update(const cv::Mat& image, Timestamp t_ns,
                                                    const std::optional<Pose2>& odometry) {
  MAPLESS_CHECK(!image.empty(), "TeachSession: empty frame");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  std::optional<route::Keyframe> out;
  features::KltPyramid pyramid = features::BuildKltPyramid(grey, options_.klt);
  if (next_index_ == 0) {
    out = MakeKeyframe(grey, t_ns, odometry);  // the first keyframe: the first frame with features
  } else {
    MAPLESS_CHECK(grey.size() == previous_.size(), "TeachSession: frame size changed from "
                                                       << previous_.cols << "x" << previous_.rows
                                                       << " to " << grey.cols << "x" << grey.rows);
    const features::KltResult tracked = Track(pyramid);
    std::vector<cv::Point2f> kept_start;
    std::vector<cv::Point2f> kept_current;
    for (std::size_t i = 0; i < current_.size(); ++i) {
      if (!tracked.ok[i]) continue;
      kept_start.push_back(start_[i]);
      kept_current.push_back(tracked.points[i]);
    }
    start_ = std::move(kept_start);
    current_ = std::move(kept_current);
    bool spread_grew = false;
    if (options_.max_spread_growth > 0.0 && start_.size() >= 2) {
      std::vector<double> xs0, xs1;
      for (std::size_t i = 0; i < start_.size(); ++i) {
        xs0.push_back(start_[i].x);
        xs1.push_back(current_[i].x);
      }
      const double s0 = control::StdDev(xs0);
      spread_grew = s0 > 1e-9 && control::StdDev(xs1) / s0 > options_.max_spread_growth;
    }
    if (tracked_fraction() < options_.keyframe_tracked_fraction || spread_grew) {
      out = MakeKeyframe(grey, t_ns, odometry);
    }
  }
  previous_is_keyframe_ = out.has_value();
  previous_ = grey.clone();
  previous_pyramid_ = std::move(pyramid);
  previous_t_ns_ = t_ns;
  previous_odometry_ = odometry;
  return out;
}

std::optional<route::Keyframe> TeachSession::Finish() {
  if (previous_.empty() || previous_is_keyframe_) return std::nullopt;
  std::optional<route::Keyframe> last = MakeKeyframe(previous_, previous_t_ns_, previous_odometry_);
  previous_is_keyframe_ = last.has_value();
  return last;
}

}  // namespace mapless::navigation

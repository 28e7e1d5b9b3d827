// The appearance route's leader (Payá et al., Section 4): route images taken while teaching, the
// eigenspace grown one image at a time. The follower is in appearance.cc.
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/navigation/appearance.h"

namespace mapless::navigation {

void AppearanceLeaderOptions::Validate() const {
  MAPLESS_CHECK(image_spacing_m > 0.0,
                "AppearanceLeaderOptions.image_spacing_m = " << image_spacing_m << "; must be > 0");
  MAPLESS_CHECK(image_turn_rad > 0.0,
                "AppearanceLeaderOptions.image_turn_rad = " << image_turn_rad << "; must be > 0");
  image.Validate();
  windows.Validate();
  pca.Validate();
}

AppearanceLeader::AppearanceLeader(AppearanceLeaderOptions options)
    : options_(options), pca_(options.pca) {
  options_.Validate();
}

bool AppearanceLeader::Update(const cv::Mat& image, const Pose2& odometry) {
  MAPLESS_CHECK(!finished_, "AppearanceLeader::Update after Finish()");
  if (have_last_) distance_m_ += odometry.DistanceTo(last_odometry_);
  last_odometry_ = odometry;
  const bool first = !have_last_;
  have_last_ = true;
  const bool far = distance_m_ - last_stored_distance_m_ >= options_.image_spacing_m - 1e-9;
  const bool turned =
      std::abs(WrapAngle(odometry.theta_rad - last_stored_.theta_rad)) >= options_.image_turn_rad;
  if (!first && !far && !turned) return false;

  // The route image is kept as the 8-bit low-resolution image (what the route store writes); the
  // model is built from it, so a follower that loads the store rebuilds exactly this model.
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = image;
  }
  cv::resize(grey, last_low_, cv::Size(options_.image.width, options_.image.height), 0, 0,
             cv::INTER_AREA);
  Add(last_low_, distance_m_, odometry);
  last_stored_ = odometry;
  last_stored_distance_m_ = distance_m_;
  return true;
}

void AppearanceLeader::AddStored(const cv::Mat& low, double distance_m, const Pose2& odometry) {
  MAPLESS_CHECK(!finished_, "AppearanceLeader::AddStored after Finish()");
  MAPLESS_CHECK(low.type() == CV_8UC1 && low.cols == options_.image.width &&
                    low.rows == options_.image.height,
                "AppearanceLeader::AddStored: a route image must be 8-bit "
                    << options_.image.width << "x" << options_.image.height);
  Add(low, distance_m, odometry);
  have_last_ = true;
  last_odometry_ = odometry;
  last_stored_ = odometry;
  distance_m_ = distance_m;
  last_stored_distance_m_ = distance_m;
}

void AppearanceLeader::AddStoredView(int place, const cv::Mat& low8, double offset_px) {
  MAPLESS_CHECK(!finished_, "AppearanceLeader::AddStoredView after Finish()");
  MAPLESS_CHECK(place >= 0 && place < images(),
                "AppearanceLeader::AddStoredView: no route image " << place);
  MAPLESS_CHECK(low8.type() == CV_8UC1 && low8.cols == options_.image.width &&
                    low8.rows == options_.image.height,
                "AppearanceLeader::AddStoredView: a view must be 8-bit "
                    << options_.image.width << "x" << options_.image.height);
  const cv::Mat low = appearance::LowResolution(low8, options_.image);
  auto view = std::make_shared<route::AppearanceRouteView>();
  view->place = place;
  view->windows = appearance::BuildSubWindowEigenspace(low, options_.windows);
  view->offset_px = offset_px;
  if (options_.incremental) {
    pca_.Add(appearance::ToVector(low));
  } else {
    vectors_.push_back(appearance::ToVector(low));
  }
  place_views_.resize(images_.size());
  place_views_[static_cast<std::size_t>(place)].push_back(static_cast<int>(views_.size()));
  views_.push_back(std::move(view));
}

void AppearanceLeader::Add(const cv::Mat& low8, double distance_m, const Pose2& odometry) {
  MAPLESS_CHECK(views_.empty(), "AppearanceLeader: a route image after a learned view");
  const cv::Mat low = appearance::LowResolution(low8, options_.image);
  const appearance::Vector vector = appearance::ToVector(low);
  auto stored = std::make_shared<route::AppearanceRouteImage>();
  stored->windows = appearance::BuildSubWindowEigenspace(low, options_.windows);
  stored->distance_m = distance_m;
  stored->odometry = odometry;
  if (options_.incremental) {
    pca_.Add(vector);
  } else {
    vectors_.push_back(vector);
  }
  images_.push_back(std::move(stored));
}

void AppearanceLeader::Finish() {
  if (finished_) return;
  finished_ = true;
  if (options_.incremental || vectors_.empty()) return;
  appearance::Matrix data(vectors_.front().size(), static_cast<Eigen::Index>(vectors_.size()));
  for (std::size_t i = 0; i < vectors_.size(); ++i)
    data.col(static_cast<Eigen::Index>(i)) = vectors_[i];
  batch_ = appearance::BatchPcaSvd(data, options_.pca.max_dimensions);
}

std::shared_ptr<const route::AppearanceRoute> AppearanceLeader::Snapshot() const {
  if (images_.empty() || (!options_.incremental && !finished_)) return nullptr;
  auto snapshot = std::make_shared<route::AppearanceRoute>();
  snapshot->space = options_.incremental ? pca_.Model() : batch_;
  snapshot->images = images_;
  snapshot->views = views_;
  snapshot->place_views = place_views_;
  snapshot->complete = finished_;
  return snapshot;
}

}  // namespace mapless::navigation

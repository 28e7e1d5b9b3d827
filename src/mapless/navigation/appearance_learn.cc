// The appearance follower's learned views (issue 45; appearance_experiences.h): which view of a
// place the current image is nearest, and when a frame is learned as a new view of its place.
// The follower itself is in appearance.cc.
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "mapless/navigation/appearance.h"

namespace mapless::navigation {
namespace {

float Distance(const route::AppearanceRoute& route, int column, const appearance::Vector& p) {
  return (route.space.projections.col(column) - p).norm();
}

}  // namespace

int AppearanceFollower::NearestPlaceIn(const route::AppearanceRoute& route, int from,
                                       int to) const {
  int best = from;
  float best_distance = std::numeric_limits<float>::infinity();
  for (int place = from; place <= to; ++place) {
    const float d = Distance(route, NearestColumnOf(route, place), projection_);
    if (d < best_distance) {
      best_distance = d;
      best = place;
    }
  }
  return best;
}

int AppearanceFollower::NearestColumnOf(const route::AppearanceRoute& route, int place) const {
  int best = place;
  float best_distance = std::numeric_limits<float>::infinity();
  for (const int column : route.ColumnsOf(place)) {
    const float d = Distance(route, column, projection_);
    if (d < best_distance) {
      best_distance = d;
      best = column;
    }
  }
  return best;
}

void AppearanceFollower::MaybeLearn(const cv::Mat& image, const cv::Mat& low,
                                    const route::AppearanceRoute& route, bool recovered,
                                    FollowerStep* step) {
  const AppearanceExperienceOptions& o = options_.experiences;
  const int place = step->index;
  const int n = route.size();
  // Sure of the place: a confident belief, steering by the place ahead (not recovering, not
  // carrying on).
  if (!options_.learn || !options_.use_markov || !route.complete || carrying_ || recovered ||
      n < 2 || place <= last_learn_place_ || step->probability < o.learn_probability) {
    return;
  }
  last_learn_place_ = place;  // one look a place a follow: the first frame sure of it
  const int nearest = NearestColumnOf(route, place);
  const float distance = Distance(route, nearest, projection_);
  // The place's own scale: how far its route image is from its nearest neighbour's.
  float neighbour = std::numeric_limits<float>::infinity();
  for (const int other : {place - 1, place + 1}) {
    if (other < 0 || other >= n) continue;
    neighbour =
        std::min(neighbour,
                 (route.space.projections.col(place) - route.space.projections.col(other)).norm());
  }
  if (!(distance > o.changed_ratio * neighbour)) return;
  // The offset: the sub-window shift of this frame against the nearest view, chained to the
  // taught image.
  const appearance::SubWindowEigenspace& windows = route.WindowsOf(nearest);
  std::vector<control::WindowCorrespondence> matches;
  for (const appearance::SubWindowMatch& m :
       appearance::MatchSubWindows(windows, low, options_.windows)) {
    matches.push_back({m.query, m.stored});
  }
  const control::SubWindowSteering fit = control::ComputeSubWindowSteering(
      matches, windows.windows(), options_.windows.step_px, options_.steering);
  if (!fit.ok) return;
  LearnedAppearanceView view;
  view.place = place;
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  // The 8-bit image a leader would have stored here (AppearanceLeader::Update).
  cv::resize(grey, view.low, cv::Size(options_.image.width, options_.image.height), 0, 0,
             cv::INTER_AREA);
  view.offset_px = fit.shift_px + route.OffsetOf(nearest);
  std::ostringstream why;
  why.precision(3);
  why << "route image " << place << " (p = " << step->probability << "): its nearest view is "
      << distance << " away, its neighbour " << neighbour << ": the place looks different today";
  view.why = why.str();
  step->learned = view.why;
  learned_.push_back(std::move(view));
}

}  // namespace mapless::navigation

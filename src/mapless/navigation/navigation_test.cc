#include <gtest/gtest.h>

#include "mapless/core/check.h"
#include "mapless/navigation/repeat.h"
#include "mapless/navigation/teach.h"
#include "mapless/sim/simulation.h"

namespace mapless::navigation {
namespace {

struct Drive {
  std::vector<cv::Mat> frames;
  std::vector<Timestamp> t_ns;
};

const Drive& TaughtFrames() {
  static const Drive drive = [] {
    Drive d;
    const sim::Scenario s = sim::LoadScenario("table1_almost_straight");
    sim::DriveTaughtPath(s, sim::DriveOptions{}, [&](const sim::DriveFrame& f) {
      d.frames.push_back(f.image);
      d.t_ns.push_back(f.t_ns);
    });
    return d;
  }();
  return drive;
}

std::shared_ptr<route::Route> Teach(const TeachOptions& options, int* deferred = nullptr) {
  auto route = std::make_shared<route::Route>();
  route->image_width = 320;
  route->image_height = 240;
  route->detector = features::DetectorTypeName(options.features.type);
  TeachSession teach(options);
  const Drive& d = TaughtFrames();
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    if (auto kf = teach.Update(d.frames[i], d.t_ns[i])) route->keyframes.push_back(*kf);
  }
  if (auto kf = teach.Finish()) route->keyframes.push_back(*kf);
  if (deferred) *deferred = teach.deferred_keyframes();
  return route;
}

TEST(TeachSession, FirstAndLastFramesAreKeyframesAndSegmentsCarryTheirTracks) {
  const auto route = Teach(TeachOptions{});
  const Drive& d = TaughtFrames();
  ASSERT_GE(route->keyframes.size(), 4u);
  EXPECT_EQ(route->keyframes.front().t_ns, d.t_ns.front());
  EXPECT_EQ(route->keyframes.back().t_ns, d.t_ns.back());
  for (std::size_t k = 0; k < route->keyframes.size(); ++k) {
    const auto& kf = route->keyframes[k];
    EXPECT_EQ(kf.index, static_cast<int>(k));
    EXPECT_GE(kf.keypoints.size(), 30u);
    EXPECT_EQ(kf.segment_start_px.size(), kf.segment_end_px.size());
    if (k > 0) {
      EXPECT_GT(kf.segment_end_px.size(), 0u) << k;
    }
    EXPECT_EQ(kf.thumbnail.cols, 160);
  }
}

// Issue 44: the features tracked in two halves on two threads give the same keyframes, bit for bit.
TEST(TeachSession, TwoThreadsTeachTheSameKeyframes) {
  const auto one = Teach(TeachOptions{});
  TeachOptions two_threads;
  two_threads.threads = 2;
  const auto two = Teach(two_threads);
  ASSERT_EQ(two->keyframes.size(), one->keyframes.size());
  for (std::size_t k = 0; k < one->keyframes.size(); ++k) {
    const auto& a = one->keyframes[k];
    const auto& b = two->keyframes[k];
    EXPECT_EQ(a.t_ns, b.t_ns) << k;
    EXPECT_EQ(a.segment_start_px, b.segment_start_px) << k;
    EXPECT_EQ(a.segment_end_px, b.segment_end_px) << k;
  }
}

TEST(TeachSession, AHigherTrackedFractionGivesDenserKeyframes) {
  TeachOptions sparse;
  sparse.keyframe_tracked_fraction = 0.4;
  TeachOptions dense;
  dense.keyframe_tracked_fraction = 0.8;
  EXPECT_GT(Teach(dense)->keyframes.size(), Teach(sparse)->keyframes.size());
}

TEST(TeachSession, FeaturelessFramesNeverBecomeKeyframes) {
  TeachSession teach(TeachOptions{});
  const Drive& d = TaughtFrames();
  ASSERT_TRUE(teach.Update(d.frames[0], 0).has_value());
  const cv::Mat blank(240, 320, CV_8UC1, cv::Scalar(90));
  // Every tracked feature is lost on a blank frame, but it has nothing to offer as a keyframe.
  EXPECT_FALSE(teach.Update(blank, 100).has_value());
  EXPECT_EQ(teach.deferred_keyframes(), 1);
  // Nor does a featureless last frame, nor a featureless first one.
  EXPECT_FALSE(teach.Finish().has_value());
  EXPECT_EQ(teach.deferred_keyframes(), 2);
  TeachSession blank_start(TeachOptions{});
  EXPECT_FALSE(blank_start.Update(blank, 0).has_value());
  EXPECT_FALSE(blank_start.Update(blank, 100).has_value());
  EXPECT_FALSE(blank_start.Finish().has_value());
  EXPECT_EQ(blank_start.keyframe_count(), 0);
  ASSERT_TRUE(blank_start.Update(d.frames[0], 200).has_value());
}

TEST(RepeatSession, ReplayingTheTaughtFramesPassesEveryKeyframe) {
  const auto route = Teach(TeachOptions{});
  RepeatSession session(route, RepeatOptions{});
  const Drive& d = TaughtFrames();
  int last_destination = 1;
  RepeatStep step;
  for (std::size_t i = 0; i < d.frames.size() && !session.finished(); ++i) {
    step = session.Update(d.frames[i], d.t_ns[i]);
    EXPECT_GE(step.destination, last_destination);  // never goes back
    last_destination = step.destination;
  }
  EXPECT_GE(last_destination, static_cast<int>(route->keyframes.size()) - 2);
}

// Experiences (issue 45): a keyframe whose taught view no longer matches but a learned view does
// is steered by the learned one (its keypoints mapped back by its offset); with learn, frames at
// the switches become views with small offsets on the taught drive itself.
TEST(RepeatSession, ALearnedViewStandsInForATaughtViewThatNoLongerMatches) {
  const auto taught = Teach(TeachOptions{});
  auto route = std::make_shared<route::Route>(*taught);
  ASSERT_GE(route->keyframes.size(), 4u);
  route::Keyframe& kf = route->keyframes[2];
  route::KeyframeView view;
  view.keypoints = kf.keypoints;
  for (auto& k : view.keypoints) k.pt.x += 8.0f;
  view.descriptors = kf.descriptors.clone();
  view.offset_px = 8.0;
  view.learned_at = view.last_used = 1;
  kf.views.push_back(view);
  route->visits = 1;
  kf.descriptors = kf.descriptors.clone();
  cv::RNG(7).fill(kf.descriptors, cv::RNG::UNIFORM, 0, 256);  // the taught view is gone
  RepeatOptions options;
  options.learn = true;
  options.experiences.changed_inliers = 100000;  // every sure switch learns
  RepeatSession session(route, options);
  const Drive& d = TaughtFrames();
  int last_destination = 1;
  bool steered_by_view = false;
  for (std::size_t i = 0; i < d.frames.size() && !session.finished(); ++i) {
    const RepeatStep step = session.Update(d.frames[i], d.t_ns[i]);
    if (step.destination == 2 && step.redetected) {
      EXPECT_EQ(step.view, 1);
      steered_by_view |= step.view == 1 && step.matches >= options.min_features;
    }
    last_destination = step.destination;
  }
  EXPECT_TRUE(steered_by_view);
  EXPECT_GE(last_destination, static_cast<int>(route->keyframes.size()) - 2);
  EXPECT_EQ(session.used_views()[2], 1);
  std::vector<LearnedView> learned = session.TakeLearned();
  ASSERT_GE(learned.size(), 2u);
  for (const auto& l : learned) {
    EXPECT_LT(std::abs(l.offset_px), 10.0) << "keyframe " << l.keyframe;
    EXPECT_NE(l.why.find("keyframe " + std::to_string(l.keyframe)), std::string::npos);
  }
  // The visit written into the route: views added, the view used at keyframe 2 marked.
  const std::size_t before = route->keyframes[2].views.size();
  ApplyVisit(route.get(), session.used_views(), learned, options.experiences);
  EXPECT_EQ(route->visits, 2);
  EXPECT_EQ(route->keyframes[2].views[0].last_used, 2);
  std::size_t views = 0;
  for (const auto& k : route->keyframes) views += k.views.size();
  EXPECT_EQ(views, before + learned.size());
}

TEST(RepeatSession, TheLocalScaleDecidesTheEndOrEveryKeyframe) {
  const auto route = Teach(TeachOptions{});
  const int last = static_cast<int>(route->keyframes.size()) - 1;
  const Drive& d = TaughtFrames();
  // Counts frames with a local scale before and on the last segment, and the destination reached.
  const auto replay = [&](const RepeatOptions& options, int* before, int* on_last) {
    RepeatSession session(route, options);
    *before = *on_last = 0;
    int destination = 1;
    for (std::size_t i = 0; i < d.frames.size() && !session.finished(); ++i) {
      const RepeatStep step = session.Update(d.frames[i], d.t_ns[i]);
      if (step.local_scale.ok) ++(step.destination == last ? *on_last : *before);
      destination = step.destination;
    }
    return destination;
  };
  int before = 0, on_last = 0;
  // Default: only the route's end.
  EXPECT_GE(replay(RepeatOptions{}, &before, &on_last), last - 1);
  EXPECT_EQ(before, 0);
  EXPECT_GT(on_last, 0);
  // Switching::kLocalScale: every segment, and the replay still passes every keyframe.
  RepeatOptions every;
  every.switching = Switching::kLocalScale;
  EXPECT_GE(replay(every, &before, &on_last), last - 1);
  EXPECT_GT(before, 20);
  // The paper's rule everywhere: no local scale at all.
  RepeatOptions paper;
  paper.end_by_local_scale = false;
  replay(paper, &before, &on_last);
  EXPECT_EQ(before + on_last, 0);
  EXPECT_EQ(ParseSwitching("scale"), Switching::kLocalScale);
  EXPECT_THROW(ParseSwitching("sideways"), InputError);
}

TEST(RepeatSession, StopsOnBlackFramesSaysWhyAndResumesWhenImagesReturn) {
  const auto route = Teach(TeachOptions{});
  RepeatSession session(route, RepeatOptions{});
  const Drive& d = TaughtFrames();
  EXPECT_EQ(session.Update(d.frames[0], 0).status, RepeatStatus::kDriving);
  const cv::Mat black(240, 320, CV_8UC1, cv::Scalar(0));
  const RepeatStep stopped = session.Update(black, FromSeconds(0.1));
  EXPECT_EQ(stopped.status, RepeatStatus::kWaiting);
  EXPECT_EQ(stopped.command.v_mps, 0.0);
  EXPECT_EQ(stopped.command.omega_radps, 0.0);
  EXPECT_NE(stopped.reason.find("camera fault: black frame"), std::string::npos) << stopped.reason;
  const RepeatStep resumed = session.Update(d.frames[1], FromSeconds(0.2));
  EXPECT_EQ(resumed.status, RepeatStatus::kDriving);
  EXPECT_GT(resumed.command.v_mps + std::abs(resumed.command.omega_radps), 0.0);
}

TEST(RepeatSession, AbortsWhenFeaturesStayMissingAndNeverDrivesBlind) {
  const auto route = Teach(TeachOptions{});
  RepeatOptions o;
  o.abort_after_s = 2.0;
  RepeatSession session(route, o);
  // A usable image (no camera fault) without a single corner: a smooth left-to-right ramp.
  cv::Mat ramp(240, 320, CV_8UC1);
  for (int x = 0; x < ramp.cols; ++x) ramp.col(x).setTo(40 + x / 2);
  RepeatStep step;
  for (int i = 0; i < 40 && !session.finished(); ++i) {
    step = session.Update(ramp, FromSeconds(0.1 * i));
    EXPECT_EQ(step.command.v_mps, 0.0);
    EXPECT_EQ(step.command.omega_radps, 0.0);
  }
  EXPECT_TRUE(session.finished());
  EXPECT_EQ(step.status, RepeatStatus::kAborted);
  EXPECT_NE(step.reason.find("aborted"), std::string::npos);
}

TEST(RepeatSession, RefusesARouteTaughtWithOtherFeaturesOrTooShort) {
  auto route = Teach(TeachOptions{});
  RepeatOptions o;
  o.features.type = features::DetectorType::kAkaze;
  EXPECT_THROW(RepeatSession(route, o), InputError);
  route->keyframes.resize(1);
  EXPECT_THROW(RepeatSession(route, RepeatOptions{}), InputError);
}

}  // namespace
}  // namespace mapless::navigation

// `mapless bench`, teach & repeat (issues 3 and 21): the teach step, the repeat step in its
// modes, the obstacle watch, against stock ORB-500 and DIS fast measured in the same run.
#include "mapless/eval/teach_repeat.h"

#include <nlohmann/json.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "mapless/bench/bench.h"
#include "mapless/bench/timing.h"
#include "mapless/features/features.h"
#include "mapless/navigation/obstacle_watch.h"
#include "mapless/navigation/repeat.h"
#include "mapless/navigation/teach.h"
#include "mapless/sim/driver.h"

namespace mapless::bench {

namespace {

std::vector<cv::Mat> GreyFrames(const std::vector<cv::Mat>& frames) {
  std::vector<cv::Mat> grey(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    grey[i] = frames[i];
    if (grey[i].channels() == 3) cv::cvtColor(frames[i], grey[i], cv::COLOR_BGR2GRAY);
  }
  return grey;
}

// The obstacle watch alone on consecutive grey frames of a drive (`forward_m` per frame), median
// ms.
double WatchMs(const std::vector<cv::Mat>& grey, double forward_m) {
  navigation::ObstacleWatchOptions on;
  on.enabled = true;
  navigation::ObstacleWatch watch(on);
  std::vector<double> ms;
  for (std::size_t i = 0; i < grey.size(); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const navigation::ObstacleCheck c = watch.Update(
        grey[i], FromSeconds(0.1 * static_cast<double>(i)), i > 0 ? forward_m : 0.0, 0.0);
    const double dt =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (c.observed) ms.push_back(dt);  // frames that compare two views (all but the first few)
  }
  return Median(ms);
}

// The obstacle watch alone (issue 21): at the teach drive's speed per frame, against DIS fast on
// the same frames (the watch's target: <= 1x DIS fast on top of the step).
void BenchObstacleWatch(const sim::Scenario& scenario, const std::vector<cv::Mat>& grey,
                        nlohmann::json* j) {
  const double forward_m = scenario.teach_speed_mps / scenario.camera.rate_hz;
  (*j)["obstacle_watch_ms"] = WatchMs(grey, forward_m);
  {
    const auto dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
    cv::Mat flow;
    (*j)["opencv_dis_fast_table1_320x240_ms"] =
        Median(TimesMs(static_cast<int>(grey.size()) - 1, [&](int i) {
          dis->calc(grey[static_cast<std::size_t>(i)], grey[static_cast<std::size_t>(i) + 1], flow);
        }));
  }
  (*j)["obstacle_watch_over_dis_fast"] = (*j)["obstacle_watch_ms"].get<double>() /
                                         (*j)["opencv_dis_fast_table1_320x240_ms"].get<double>();
}

// `route`'s keyframes repeated `times` times (a long route of the same segments).
std::shared_ptr<route::Route> LongRoute(const route::Route& route, int times) {
  auto long_route = std::make_shared<route::Route>(route);
  long_route->keyframes.clear();
  for (int k = 0; k < times; ++k) {
    for (const auto& kf : route.keyframes) {
      route::Keyframe copy = kf;
      copy.index = static_cast<int>(long_route->keyframes.size());
      long_route->keyframes.push_back(copy);
    }
  }
  return long_route;
}

// mapless's ORB settings (the FAST threshold 10) by OpenCV and by OrbDetector, which gives the
// same keypoints and descriptors (features/orb.h), on the same grey frames, interleaved frame by
// frame so that both see the same host speed.
void BenchOrbSettings(const std::vector<cv::Mat>& grey, nlohmann::json* j) {
  std::vector<cv::KeyPoint> kp;
  cv::Mat desc;
  const features::FeatureOptions fo;
  auto opencv = cv::ORB::create(fo.max_features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31,
                                fo.orb_fast_threshold);
  const features::OrbDetector ours(fo.max_features, fo.orb_fast_threshold);
  // Interleaved, frame by frame, so both see the same host speed.
  std::vector<double> theirs_ms, ours_ms;
  for (int i = 0; i < 120; ++i) {
    const cv::Mat& g = grey[static_cast<std::size_t>(i) % grey.size()];
    theirs_ms.push_back(
        TimesMs(1, [&](int) { opencv->detectAndCompute(g, cv::noArray(), kp, desc); })[0]);
    ours_ms.push_back(TimesMs(1, [&](int) { ours.DetectAndCompute(g, &kp, &desc); })[0]);
  }
  (*j)["opencv_orb_mapless_settings_320x240_ms"] = Median(theirs_ms);
  (*j)["orb_detector_320x240_ms"] = Median(ours_ms);
  (*j)["orb_detector_over_opencv_same_settings"] =
      (*j)["orb_detector_320x240_ms"].get<double>() /
      (*j)["opencv_orb_mapless_settings_320x240_ms"].get<double>();
}

// Times `one(i)`, `two(i)` and stock ORB-500 on frame i, one right after the other, for every
// frame while `more()` holds: the three medians see the same load.
struct Interleaved {
  std::vector<double> one, two, orb;
};
Interleaved TimeInterleaved(
    const std::vector<cv::Mat>& frames, const std::function<void(std::size_t)>& one,
    const std::function<void(std::size_t)>& two,
    const std::function<bool()>& more = [] { return true; }) {
  auto stock_orb = cv::ORB::create(500);
  std::vector<cv::KeyPoint> kp;
  cv::Mat desc;
  Interleaved t;
  for (std::size_t i = 0; i < frames.size() && more(); ++i) {
    t.one.push_back(TimesMs(1, [&](int) { one(i); })[0]);
    t.two.push_back(TimesMs(1, [&](int) { two(i); })[0]);
    t.orb.push_back(TimesMs(
        1, [&](int) { stock_orb->detectAndCompute(frames[i], cv::noArray(), kp, desc); })[0]);
  }
  return t;
}

// Teach: KLT tracking + keyframe test per frame (keyframe frames also detect and describe), with
// stock ORB-500 timed on the same frame right after each step.
void BenchTeachStep(const std::vector<cv::Mat>& frames, nlohmann::json* j) {
  // TeachOptions::threads 2 (the features tracked in two halves, the same keyframes) is timed on
  // the same frame right after the one-thread step, so both see the same load.
  navigation::TeachSession teach(navigation::TeachOptions{});
  navigation::TeachOptions two_threads;
  two_threads.threads = 2;
  navigation::TeachSession two(two_threads);
  const auto at = [](std::size_t i) { return FromSeconds(0.1 * static_cast<double>(i)); };
  const Interleaved t = TimeInterleaved(
      frames, [&](std::size_t i) { teach.Update(frames[i], at(i)); },
      [&](std::size_t i) { two.Update(frames[i], at(i)); });
  (*j)["teach_step_ms"] = Median(t.one);
  (*j)["teach_step_over_orb_interleaved"] = Median(t.one) / Median(t.orb);
  (*j)["teach_step_2_threads_ms"] = Median(t.two);
  (*j)["teach_step_2_threads_over_orb_interleaved"] = Median(t.two) / Median(t.orb);
}

// Experiences (issue 45): the default step on the route with 4 learned views per keyframe (5
// views) against the step with the taught view alone, the two sessions stepped on the same frame
// one right after the other (a host whose speed drifts moves both alike). The views are the taught
// features moved 6 px sideways, with that offset: each matches as well as the taught view, the
// most the choice among views can cost.
void BenchViews(const std::shared_ptr<const route::Route>& taught,
                const std::vector<cv::Mat>& frames, nlohmann::json* j) {
  auto views = std::make_shared<route::Route>(*taught);
  for (auto& kf : views->keyframes) {
    for (int v = 1; v <= 4; ++v) {
      route::KeyframeView view;
      view.keypoints = kf.keypoints;
      for (auto& k : view.keypoints) k.pt.x += 6.0f * static_cast<float>(v);
      view.descriptors = kf.descriptors;
      view.offset_px = 6.0 * v;
      view.learned_at = view.last_used = v;
      kf.views.push_back(std::move(view));
    }
  }
  views->visits = 4;
  navigation::RepeatOptions o;
  o.obstacle.enabled = false;
  navigation::RepeatSession one(taught, o);
  navigation::RepeatSession five(views, o);
  std::vector<double> one_ms, five_ms;
  const auto time = [](navigation::RepeatSession* s, const cv::Mat& frame, Timestamp t,
                       std::vector<double>* ms) {
    const auto t0 = std::chrono::steady_clock::now();
    s->Update(frame, t);
    ms->push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  };
  for (std::size_t i = 0; i < frames.size() && !one.finished() && !five.finished(); ++i) {
    time(&one, frames[i], FromSeconds(0.1 * static_cast<double>(i)), &one_ms);
    time(&five, frames[i], FromSeconds(0.1 * static_cast<double>(i)), &five_ms);
  }
  const auto mean = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (const double x : v) sum += x;
    return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
  };
  (*j)["repeat_step_1_view_ms"] = Median(one_ms);
  (*j)["repeat_step_5_views_ms"] = Median(five_ms);
  (*j)["repeat_step_5_views_over_1"] = Median(five_ms) / Median(one_ms);
  (*j)["repeat_step_5_views_over_1_mean"] = mean(five_ms) / mean(one_ms);
}

// What `repeat` runs by default: the step with the obstacle watch, on one thread and with
// RepeatOptions::threads 2 (the watch beside the feature detection, the only repeat row with a
// second thread; the same decisions), each timed on the same frame, then stock ORB-500.
void BenchWatchStep(const std::shared_ptr<const route::Route>& route,
                    const std::vector<cv::Mat>& frames, nlohmann::json* j) {
  navigation::RepeatOptions o;
  navigation::RepeatSession one(route, o);
  o.threads = 2;
  navigation::RepeatSession two(route, o);
  const auto at = [](std::size_t i) { return FromSeconds(0.1 * static_cast<double>(i)); };
  const Interleaved t = TimeInterleaved(
      frames, [&](std::size_t i) { one.Update(frames[i], at(i)); },
      [&](std::size_t i) { two.Update(frames[i], at(i)); },
      [&] { return !one.finished() && !two.finished(); });
  (*j)["repeat_step_default_with_watch_ms"] = Median(t.one);
  (*j)["repeat_step_default_with_watch_over_orb_interleaved"] = Median(t.one) / Median(t.orb);
  (*j)["repeat_step_default_with_watch_2_threads_ms"] = Median(t.two);
  (*j)["repeat_step_default_with_watch_2_threads_over_orb_interleaved"] =
      Median(t.two) / Median(t.orb);
}

}  // namespace

// Teach & repeat stages (issue 3) on the frames of the table1_almost_straight teach drive; the
// method's rows without the obstacle watch (as in the papers), the watch in rows of its own.
void BenchTeachRepeat(nlohmann::json* j) {
  const sim::Scenario scenario = BenchScenario("table1_almost_straight");
  std::vector<cv::Mat> frames;
  sim::DriveTaughtPath(scenario, {}, [&](const sim::DriveFrame& f) { frames.push_back(f.image); });
  const int n = static_cast<int>(frames.size());
  const eval::TaughtRoute taught = eval::TeachOnSimulator(scenario, navigation::TeachOptions{});
  // With `orb_ms`, stock ORB-500 is timed on the same frame right after each counted step: a
  // reference measured at the same moments as the step, so a host whose speed drifts during the run
  // (a shared virtual machine) moves both alike.
  auto stock_orb = cv::ORB::create(500);
  std::vector<cv::KeyPoint> kp;
  cv::Mat desc;
  auto time_stock_orb = [&](const cv::Mat& frame, std::vector<double>* orb_ms) {
    const auto t0 = std::chrono::steady_clock::now();
    stock_orb->detectAndCompute(frame, cv::noArray(), kp, desc);
    orb_ms->push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  };
  BenchTeachStep(frames, j);
  // Repeat along the taught frames: in-segment KLT tracking + control (Algorithm 1 as written).
  auto repeat_median = [&](std::shared_ptr<const route::Route> route, int redetect,
                           bool only_tracking, bool only_last = false,
                           std::vector<double>* orb_ms = nullptr) {
    navigation::RepeatOptions o;
    o.redetect_every_frames = redetect;
    o.obstacle.enabled = false;
    navigation::RepeatSession session(route, o);
    std::vector<double> ms;
    for (int i = 0; i < n; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const navigation::RepeatStep step =
          session.Update(frames[static_cast<std::size_t>(i)], FromSeconds(0.1 * i));
      const double dt =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      const bool last = step.destination + 1 == static_cast<int>(route->keyframes.size());
      if ((!only_tracking || !step.redetected) && (!only_last || last)) {
        ms.push_back(dt);
        if (orb_ms != nullptr) time_stock_orb(frames[static_cast<std::size_t>(i)], orb_ms);
      }
      if (session.finished()) break;
    }
    return Median(ms);
  };
  // The default step (RepeatOptions{}): KLT tracking with fresh matching every
  // redetect_every_frames frames; every frame counts. Median, mean and 90th percentile: the
  // frames that detect afresh cost more than the others.
  const auto default_step = [&](std::vector<double>* orb_ms) {
    navigation::RepeatOptions o;
    o.obstacle.enabled = false;
    navigation::RepeatSession session(taught.route, o);
    std::vector<double> ms;
    for (int i = 0; i < n && !session.finished(); ++i) {
      const cv::Mat& frame = frames[static_cast<std::size_t>(i)];
      const auto t0 = std::chrono::steady_clock::now();
      session.Update(frame, FromSeconds(0.1 * i));
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (orb_ms != nullptr) time_stock_orb(frame, orb_ms);
    }
    return ms;
  };
  {
    std::vector<double> orb_interleaved;
    std::vector<double> ms = default_step(&orb_interleaved);
    (*j)["opencv_orb500_interleaved_ms"] = Median(orb_interleaved);
    (*j)["repeat_step_default_over_orb_interleaved"] =
        Median(ms) / (*j)["opencv_orb500_interleaved_ms"].get<double>();
    double sum = 0.0;
    for (const double v : ms) sum += v;
    (*j)["repeat_step_default_ms"] = Median(ms);
    (*j)["repeat_step_default_mean_ms"] = ms.empty() ? 0.0 : sum / static_cast<double>(ms.size());
    std::sort(ms.begin(), ms.end());
    (*j)["repeat_step_default_p90_ms"] =
        ms.empty() ? 0.0 : ms[static_cast<std::size_t>(0.9 * static_cast<double>(ms.size() - 1))];
  }
  BenchWatchStep(taught.route, frames, j);
  BenchViews(taught.route, frames, j);
  const std::vector<cv::Mat> grey = GreyFrames(frames);
  BenchObstacleWatch(scenario, grey, j);
  {
    std::vector<double> orb_interleaved;
    (*j)["repeat_step_ms"] = repeat_median(taught.route, 0, true, false, &orb_interleaved);
    (*j)["repeat_step_over_orb_interleaved"] =
        (*j)["repeat_step_ms"].get<double>() / Median(orb_interleaved);
  }
  (*j)["repeat_step_fresh_ms"] = repeat_median(taught.route, 1, false);
  // The last segment, where the local scale of nearby feature pairs also decides the route's end.
  (*j)["repeat_step_fresh_end_ms"] = repeat_median(taught.route, 1, false, true);
  // The same on a 1 km route (the 10 m route's keyframes repeated 100 times): the per-frame cost
  // depends only on the current segment.
  const auto long_route = LongRoute(*taught.route, 100);
  (*j)["route_1km_keyframes"] = long_route->keyframes.size();
  (*j)["repeat_step_1km_ms"] = repeat_median(long_route, 0, true);
  (*j)["repeat_step_fresh_1km_ms"] = repeat_median(long_route, 1, false);
  // Segment start: detect + describe the current frame, match it with the destination keyframe,
  // reject outliers. Measured as the first Update of a fresh session (which does exactly that).
  (*j)["segment_start_ms"] = Median(TimesMs(40, [&](int i) {
    navigation::RepeatSession session(taught.route, navigation::RepeatOptions{});
    session.Update(frames[static_cast<std::size_t>(i % std::max(1, n / 2))], 0);
  }));
  (*j)["opencv_orb500_320x240_ms"] = Median(TimesMs(60, [&](int i) {
    stock_orb->detectAndCompute(frames[static_cast<std::size_t>(i % n)], cv::noArray(), kp, desc);
  }));
  const double orb_ms = (*j)["opencv_orb500_320x240_ms"].get<double>();
  BenchOrbSettings(grey, j);
  (*j)["orb_detector_over_orb"] = (*j)["orb_detector_320x240_ms"].get<double>() / orb_ms;
  (*j)["repeat_step_over_orb"] = (*j)["repeat_step_ms"].get<double>() / orb_ms;
  (*j)["repeat_step_default_over_orb"] = (*j)["repeat_step_default_ms"].get<double>() / orb_ms;
  (*j)["repeat_step_default_mean_over_orb"] =
      (*j)["repeat_step_default_mean_ms"].get<double>() / orb_ms;
  (*j)["repeat_step_fresh_over_orb"] = (*j)["repeat_step_fresh_ms"].get<double>() / orb_ms;
  (*j)["segment_start_over_orb"] = (*j)["segment_start_ms"].get<double>() / orb_ms;
}

}  // namespace mapless::bench

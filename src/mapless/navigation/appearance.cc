#include "mapless/navigation/appearance.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/localization/nearest.h"

namespace mapless::navigation {
namespace {

// Signed distance from `from` to `to` along `from`'s heading (odometry between two frames).
double AdvanceAlong(const Pose2& from, const Pose2& to) {
  return (to.x_m - from.x_m) * std::cos(from.theta_rad) +
         (to.y_m - from.y_m) * std::sin(from.theta_rad);
}

}  // namespace

// ---- Follower ----------------------------------------------------------------------------------

const char* FollowerStateName(FollowerState state) {
  switch (state) {
    case FollowerState::kInitializing:
      return "initializing";
    case FollowerState::kFollowing:
      return "following";
    case FollowerState::kStopped:
      return "stopped";
    case FollowerState::kWaitingForLeader:
      return "waiting_for_leader";
    case FollowerState::kArrived:
      return "arrived";
  }
  return "?";
}

void AppearanceFollowerOptions::Validate() const {
  image.Validate();
  windows.Validate();
  steering.Validate();
  camera.Validate();
  obstacle.Validate();
  markov.Validate();
  clustering.Validate();
  MAPLESS_CHECK(
      init_turn_rad >= 0.0 && init_turn_rad < kPi,
      "AppearanceFollowerOptions.init_turn_rad = " << init_turn_rad << "; must be in [0, pi)");
  MAPLESS_CHECK(init_turn_rate_radps > 0.0, "AppearanceFollowerOptions.init_turn_rate_radps = "
                                                << init_turn_rate_radps << "; must be > 0");
  MAPLESS_CHECK(init_forward_m >= 0.0, "AppearanceFollowerOptions.init_forward_m = "
                                           << init_forward_m << "; must be >= 0");
  MAPLESS_CHECK(init_forward_speed_mps > 0.0, "AppearanceFollowerOptions.init_forward_speed_mps = "
                                                  << init_forward_speed_mps << "; must be > 0");
  MAPLESS_CHECK(init_sigma_images > 0.0, "AppearanceFollowerOptions.init_sigma_images = "
                                             << init_sigma_images << "; must be > 0");
  MAPLESS_CHECK(start_window_m >= 0.0, "AppearanceFollowerOptions.start_window_m = "
                                           << start_window_m << "; must be >= 0");
  MAPLESS_CHECK(arrive_min_probability >= 0.0 && arrive_min_probability <= 1.0,
                "AppearanceFollowerOptions.arrive_min_probability = " << arrive_min_probability
                                                                      << "; must be in [0, 1]");
  MAPLESS_CHECK(min_follow_frames >= 0, "AppearanceFollowerOptions.min_follow_frames = "
                                            << min_follow_frames << "; must be >= 0");
  MAPLESS_CHECK(min_contrast >= 0.0,
                "AppearanceFollowerOptions.min_contrast = " << min_contrast << "; must be >= 0");
  MAPLESS_CHECK(relocalize_after_stopped_frames >= 1,
                "AppearanceFollowerOptions.relocalize_after_stopped_frames = "
                    << relocalize_after_stopped_frames << "; must be >= 1");
  MAPLESS_CHECK(uniform_mixing_for_m >= 0.0, "AppearanceFollowerOptions.uniform_mixing_for_m = "
                                                 << uniform_mixing_for_m << "; must be >= 0");
  MAPLESS_CHECK(behind_fraction >= 0.0, "AppearanceFollowerOptions.behind_fraction = "
                                            << behind_fraction << "; must be >= 0");
  MAPLESS_CHECK(ahead_fraction >= 0.0, "AppearanceFollowerOptions.ahead_fraction = "
                                           << ahead_fraction << "; must be >= 0");
  MAPLESS_CHECK(anchor_probability > 0.0 && anchor_probability <= 1.0,
                "AppearanceFollowerOptions.anchor_probability = " << anchor_probability
                                                                  << "; must be in (0, 1]");
  MAPLESS_CHECK(anchor_end_m >= 0.0,
                "AppearanceFollowerOptions.anchor_end_m = " << anchor_end_m << "; must be >= 0");
  MAPLESS_CHECK(markov_update_images >= 0.0, "AppearanceFollowerOptions.markov_update_images = "
                                                 << markov_update_images << "; must be >= 0");
  MAPLESS_CHECK(lookahead_images >= 0, "AppearanceFollowerOptions.lookahead_images = "
                                           << lookahead_images << "; must be >= 0");
  MAPLESS_CHECK(arrive_within_images >= 0, "AppearanceFollowerOptions.arrive_within_images = "
                                               << arrive_within_images << "; must be >= 0");
  MAPLESS_CHECK(wait_within_images >= 0, "AppearanceFollowerOptions.wait_within_images = "
                                             << wait_within_images << "; must be >= 0");
  MAPLESS_CHECK(carry_on_heading_frames >= 1, "AppearanceFollowerOptions.carry_on_heading_frames = "
                                                  << carry_on_heading_frames << "; must be >= 1");
  MAPLESS_CHECK(recover_images >= 0, "AppearanceFollowerOptions.recover_images = "
                                         << recover_images << "; must be >= 0");
  carry_on.Validate();
  MAPLESS_CHECK(turn_in_place_min_rad > 0.0 && turn_in_place_max_m >= 0.0 &&
                    turn_in_place_tolerance_rad > 0.0 && turn_in_place_rate_radps > 0.0,
                "AppearanceFollowerOptions.turn_in_place_min_rad = "
                    << turn_in_place_min_rad << ", turn_in_place_max_m = " << turn_in_place_max_m
                    << ", turn_in_place_tolerance_rad = " << turn_in_place_tolerance_rad
                    << ", turn_in_place_rate_radps = " << turn_in_place_rate_radps
                    << "; must be > 0, >= 0, > 0 and > 0");
  experiences.Validate();
}

AppearanceFollowerOptions::AppearanceFollowerOptions() {
  // With uniform_mixing_for_m > 0, 1% of the belief is spread uniformly at each prediction during
  // the first uniform_mixing_for_m after each localization, so that a wrong belief (an aliased
  // twin) can give way. It was on (12 m) until the ahead limit (ahead_margin_m) existed: on the
  // office route the follower that starts 1 m behind the route start sees what the route sees
  // 2 m in, so its belief ran ahead onto the twin 3 m further, and the mixing let it come back
  // once the far end told the places apart. The limit stops the running ahead; the mixing then
  // only let the belief jump onto the twin 3 m behind (measured, 10 runs, office off-route
  // left/right: localization within one image 0.86/0.99 with the mixing, 0.99/1.00 without).
  // The same mixing ruins sequence localization with weak observations (Nordland winter on
  // summer 0.90 -> 0.19), so MarkovOptions keeps 0.
  markov.uniform_mixing = 0.01;
  // The obstacle watch compares frames 0.12 m apart instead of the repeat's 0.08: about 0.4 s of
  // driving at each method's speed (the follower 0.3 m/s, the repeat suites 0.2 m/s). With 0.08
  // the follower saw a 0.5 m box only 1 m ahead and ran into it (obstacle_box_office, 2 of 2
  // runs); with 0.12 and 0.16 it stopped 0.7-0.8 m before it (docs/appearance_route_following.md).
  obstacle.baseline_m = 0.12;
  // Stop when the ground ahead went unchecked for 0.5 m (obstacle_watch.h): on lifelong_indoor,
  // followed on session 19 with the route of session 0, the lost follower crept 0.75 m towards a
  // tiled wall with too few points tracked in the region to check it, and touched it.
  obstacle.max_unchecked_m = 0.5;
}

AppearanceFollower::AppearanceFollower(AppearanceFollowerOptions options)
    : options_(options),
      camera_(options.camera),
      watch_(options.obstacle),
      markov_(options.markov) {
  options_.Validate();
}

void AppearanceFollower::StartInitialization(const Pose2& odometry, int centre_index) {
  initializing_ = true;
  init_centre_ = centre_index;
  stopped_frames_ = 0;
  init_started_ = true;
  init_phase_ = 0;
  init_start_ = odometry;
  init_localizations_.clear();
}

FollowerStep AppearanceFollower::Initialize(const appearance::Vector& projection,
                                            const Pose2& odometry,
                                            const route::AppearanceRoute& route) {
  FollowerStep step;
  step.state = FollowerState::kInitializing;
  if (!init_started_) StartInitialization(odometry, init_centre_);
  // Candidates: route images within start_window_m of the start (first localization) or of the
  // position where the follower lost its footing (later ones).
  int from = 0;
  int to = route.size() - 1;
  if (options_.start_window_m > 0.0 && route.SpacingM() > 0.0) {
    const int w = static_cast<int>(std::lround(options_.start_window_m / route.SpacingM()));
    from = std::clamp(init_centre_ < 0 ? 0 : init_centre_ - w, 0, route.size() - 1);
    to = std::clamp(init_centre_ < 0 ? w : init_centre_ + w, from, route.size() - 1);
  }
  init_localizations_.push_back(
      route.has_views()
          ? NearestPlaceIn(route, from, to)
          : from + localization::NearestProjection(
                       route.space.projections.middleCols(from, to - from + 1), projection)
                       .index);
  step.index = init_localizations_.back();
  const double turned = WrapAngle(odometry.theta_rad - init_start_.theta_rad);
  const double theta = options_.init_turn_rad;
  const double rate = options_.init_turn_rate_radps;
  // Small turns and a short creep around the start (Section 4, Fig. 6), one phase after another.
  if (init_phase_ == 0 && turned >= theta) init_phase_ = 1;
  if (init_phase_ == 1 && turned <= -theta) init_phase_ = 2;
  if (init_phase_ == 2 && turned >= 0.0) init_phase_ = 3;
  if (init_phase_ == 3 && odometry.DistanceTo(init_start_) >= options_.init_forward_m)
    init_phase_ = 4;
  switch (init_phase_) {
    case 0:
    case 2:
      step.command.omega_radps = std::min(rate, 2.0 * std::abs(theta - turned) + 0.05);
      return step;
    case 1:
      step.command.omega_radps = -std::min(rate, 2.0 * std::abs(-theta - turned) + 0.05);
      return step;
    case 3:
      step.command.v_mps = options_.init_forward_speed_mps;
      return step;
    default:
      break;
  }
  const localization::InitialLocalization init =
      localization::LocalizeByClustering(init_localizations_, options_.clustering);
  if (!init.ok) {
    init_started_ = false;  // try again from here
    step.reason = "initial localization failed: " + init.reason;
    return step;
  }
  markov_.ResetAt(route.size(), init.index, options_.init_sigma_images);
  if (init_centre_ < 0) {
    // The start localization: from here on the robot cannot get further along the route than it
    // drives (ahead_margin_m); localizing again later does not move this reference.
    start_index_ = init.index;
    driven_m_ = 0.0;
  }
  since_localized_m_ = 0.0;
  anchor_index_ = -1;  // the next confident belief anchors the lower limit again
  have_localization_ = false;
  carrying_.reset();
  carry_given_up_ = false;
  pending_advance_images_ = 0.0;
  initializing_ = false;
  init_started_ = false;
  step.index = init.index;
  step.reason = "localized at route image " + std::to_string(init.index);
  return step;
}

FollowerStep AppearanceFollower::Update(const cv::Mat& image, const Pose2& odometry,
                                        const route::AppearanceRoute& route, Timestamp t_ns) {
  FollowerStep step;
  const CameraCheck camera = camera_.Check(image, last_command_);
  if (arrived_) {
    step.state = FollowerState::kArrived;
  } else if (!camera.usable()) {
    step.state = initializing_ ? FollowerState::kInitializing : FollowerState::kStopped;
    step.reason = camera.reason;
  } else {
    // The obstacle watch first (not while localizing at the start: the robot only turns and
    // creeps there): a blocked follower neither localizes nor steers, and resumes where it was.
    ObstacleCheck obstacle;
    if (!initializing_) {
      cv::Mat grey = image;
      if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
      double forward_m = 0.0;
      double turned_rad = 0.0;
      if (have_watch_odometry_) {
        forward_m = AdvanceAlong(watch_odometry_, odometry);
        // Signed: the watch compares the heading between two frames (obstacle_watch.cc).
        turned_rad = WrapAngle(odometry.theta_rad - watch_odometry_.theta_rad);
      }
      obstacle = watch_.Update(grey, t_ns, forward_m, turned_rad);
    }
    have_watch_odometry_ = true;
    watch_odometry_ = odometry;
    if (obstacle.blocked && BlockedAtTheEnd(route)) {
      arrived_ = true;
      step.state = FollowerState::kArrived;
      step.index = last_localization_.index;
      step.probability = last_localization_.probability;
      step.reason = "arrived: stopped at route image " + std::to_string(step.index) + " of " +
                    std::to_string(route.size()) + " before something beyond the route's end (" +
                    obstacle.reason + ")";
    } else if (obstacle.blocked) {
      step.state = FollowerState::kStopped;
      step.reason = obstacle.reason;
    } else {
      step = Decide(image, odometry, route);
      if (obstacle.creeping && step.state == FollowerState::kFollowing) {
        // Straight ahead, slowly, until the watch has checked the ground (obstacle_watch.h); the
        // follower goes on localizing meanwhile.
        step.command = Twist2{options_.obstacle.CreepSpeedMps(), 0.0};
        step.reason = obstacle.reason;
      }
    }
    step.obstacle = obstacle;
  }
  last_command_ = step.command;
  return step;
}

bool AppearanceFollower::BlockedAtTheEnd(const route::AppearanceRoute& route) const {
  return options_.arrive_blocked_within_images >= 0 && route.complete && have_localization_ &&
         follow_frames_ >= options_.min_follow_frames &&
         last_localization_.index >= route.size() - 1 - options_.arrive_blocked_within_images;
}

// Where on the route the robot is: Payá et al.'s Markov localization over the route images (one
// Bayes update per markov_update_images of travel, within the window the distance driven allows),
// or the nearest projection. False when the localization is lost (the step says so).
bool AppearanceFollower::Localize(const appearance::Vector& projection, double advance_m,
                                  const Pose2& odometry, const route::AppearanceRoute& route,
                                  FollowerStep* step) {
  const int n = route.size();
  if (options_.use_markov) {
    const double spacing = std::max(route.SpacingM(), 1e-3);
    pending_advance_images_ += advance_m / spacing;
    // One Bayes update per markov_update_images of travel: consecutive frames see nearly the same
    // image and their errors are not independent (updating at every frame counts the same
    // evidence many times over).
    if (!have_localization_ || std::abs(pending_advance_images_) >= options_.markov_update_images ||
        route.size() != last_route_size_) {
      if (options_.ahead_margin_m >= 0.0 && options_.start_window_m > 0.0 && start_index_ >= 0) {
        const double ahead_m =
            driven_m_ * (1.0 + options_.ahead_fraction) + options_.ahead_margin_m;
        const double behind_m = driven_m_ * (1.0 - options_.behind_fraction) -
                                options_.ahead_margin_m - options_.start_window_m;
        int lowest = start_index_ + static_cast<int>(std::floor(behind_m / spacing));
        if (anchor_index_ >= 0) {
          const double since_m = (driven_m_ - anchor_driven_m_) * (1.0 - options_.behind_fraction) -
                                 options_.ahead_margin_m;
          lowest =
              std::max(lowest, anchor_index_ + static_cast<int>(std::floor(since_m / spacing)));
        }
        markov_.set_index_limits(options_.behind_fraction < 1.0 ? lowest : -1,
                                 start_index_ + static_cast<int>(std::ceil(ahead_m / spacing)));
      }
      markov_.set_uniform_mixing(since_localized_m_ < options_.uniform_mixing_for_m
                                     ? options_.markov.uniform_mixing
                                     : 0.0);
      // Carrying on: the images are known not to fit here, so the belief moves by odometry alone.
      if (carrying_) {
        last_localization_ = markov_.Predict(route.size(), pending_advance_images_);
      } else if (route.has_views()) {
        // Over places: a place is as near as its nearest view (appearance_experiences.h).
        last_localization_ = markov_.Update(route.space.projections, route.ColumnPlaces(),
                                            route.size(), projection, pending_advance_images_);
      } else {
        last_localization_ =
            markov_.Update(route.space.projections, projection, pending_advance_images_);
      }
      pending_advance_images_ = 0.0;
      have_localization_ = true;
      last_route_size_ = route.size();
      // Near the end of a complete route (AppearanceFollowerOptions::anchor_end_m).
      const int end_images = static_cast<int>(std::ceil(options_.anchor_end_m / spacing));
      if (options_.anchor_end_m > 0.0 && route.complete && !carrying_ &&
          driven_m_ >= options_.start_window_m + options_.ahead_margin_m &&
          last_localization_.index >= n - 1 - end_images &&
          last_localization_.status == localization::LocalizationStatus::kTracking &&
          last_localization_.probability >= options_.anchor_probability &&
          last_localization_.index > anchor_index_) {
        anchor_index_ = last_localization_.index;
        anchor_driven_m_ = driven_m_;
      }
    }
    const localization::Localization& loc = last_localization_;
    step->index =
        std::clamp(loc.index + static_cast<int>(std::lround(pending_advance_images_)), 0, n - 1);
    step->probability = loc.probability;
    const Eigen::VectorXd& belief = markov_.belief();
    step->belief.resize(static_cast<std::size_t>(belief.size()));
    for (Eigen::Index i = 0; i < belief.size(); ++i)
      step->belief[static_cast<std::size_t>(i)] = static_cast<float>(belief[i]);
    if (loc.status == localization::LocalizationStatus::kLost) {
      StartInitialization(odometry, loc.index);
      step->state = FollowerState::kStopped;
      step->reason = "localization lost (probability " + std::to_string(loc.probability) +
                     "); localizing again";
      return false;
    }
  } else {
    const std::vector<localization::Neighbour> nn =
        route.has_views()
            ? localization::NearestPlaces(route.space.projections, route.ColumnPlaces(),
                                          route.size(), projection, 2)
            : localization::NearestProjections(route.space.projections, projection, 2);
    step->index = nn.front().index;
    step->probability = nn.size() > 1 && nn[1].distance > 0.0F
                            ? 1.0 - static_cast<double>(nn[0].distance) / nn[1].distance
                            : 1.0;
  }
  return true;
}

FollowerStep AppearanceFollower::Decide(const cv::Mat& image, const Pose2& odometry,
                                        const route::AppearanceRoute& route) {
  double advance_m = 0.0;
  if (have_odometry_) {
    // Signed distance along the previous heading.
    advance_m = AdvanceAlong(last_odometry_, odometry);
  }
  have_odometry_ = true;
  last_odometry_ = odometry;
  since_localized_m_ += std::abs(advance_m);
  driven_m_ += std::abs(advance_m);

  FollowerStep step;
  if (arrived_) {
    step.state = FollowerState::kArrived;
    return step;
  }
  if (route.size() < 2) {
    step.state = FollowerState::kWaitingForLeader;
    step.reason = "the route has fewer than 2 images";
    return step;
  }
  cv::Scalar mean;
  cv::Scalar contrast;
  cv::meanStdDev(image, mean, contrast);
  if (contrast[0] < options_.min_contrast) {
    // Black, over-exposed or a featureless wall: nothing to localize or steer by.
    step.state = initializing_ ? FollowerState::kInitializing : FollowerState::kStopped;
    step.reason = "the camera image has no contrast (standard deviation " +
                  std::to_string(contrast[0]) + " grey levels)";
    return step;
  }
  const cv::Mat low = appearance::LowResolution(image, options_.image);
  const appearance::Vector projection = route.space.Project(appearance::ToVector(low));
  projection_ = projection;
  if (initializing_) return Initialize(projection, odometry, route);

  const int n = route.size();
  if (!Localize(projection, advance_m, odometry, route, &step)) return step;
  ++follow_frames_;
  const bool limited = options_.use_markov && options_.ahead_margin_m >= 0.0 &&
                       options_.start_window_m > 0.0 && start_index_ >= 0;
  const bool driven_enough =
      !limited || options_.arrive_odometry_slack_m < 0.0 ||
      driven_m_ >= (n - 1 - start_index_) * route.SpacingM() - options_.arrive_odometry_slack_m;
  if (route.complete && step.index >= n - 1 - options_.arrive_within_images &&
      follow_frames_ >= options_.min_follow_frames && driven_enough &&
      (!options_.use_markov || step.probability >= options_.arrive_min_probability)) {
    arrived_ = true;
    step.state = FollowerState::kArrived;
    return step;
  }
  if (!route.complete && step.index >= n - 1 - options_.wait_within_images) {
    step.state = FollowerState::kWaitingForLeader;
    step.reason = "at route image " + std::to_string(step.index) + " of " + std::to_string(n) +
                  " still being taught";
    return step;
  }
  if (const std::optional<Twist2> turn = TurnInPlace(odometry, route, &step)) {
    stopped_frames_ = 0;
    step.state = FollowerState::kFollowing;
    step.command = *turn;
    return step;
  }
  // Steer towards the route image lookahead_images ahead; when its sub-windows give no
  // consistent fit, try its neighbours (the localization is good to about one image), then the
  // route images beyond them (recovery), then carry on along the leader's odometry.
  const int ahead = std::min(step.index + options_.lookahead_images, n - 1);
  const bool steered = SteerTowards({ahead, ahead - 1, ahead + 1}, low, route, &step);
  const bool recovered = !steered && Recover(ahead, low, route, &step);
  if (steered || recovered) {
    carrying_.reset();
    carry_given_up_ = false;
  } else if (const std::optional<Twist2> carry = CarryOn(odometry, route, &step)) {
    stopped_frames_ = 0;
    step.state = FollowerState::kFollowing;
    step.command = *carry;
    return step;
  } else {
    // Safety: no steering decision, so the robot stops and says why; if that lasts, it makes the
    // small motions of the initial localization around its current position, which also change
    // the view.
    step.state = FollowerState::kStopped;
    step.reason = step.steering.reason;
    if (++stopped_frames_ >= options_.relocalize_after_stopped_frames) {
      StartInitialization(odometry, step.index);
      step.reason += "; localizing again around route image " + std::to_string(step.index);
    }
    return step;
  }
  stopped_frames_ = 0;
  step.state = FollowerState::kFollowing;
  step.command = step.steering.twist;
  if (options_.leader_turn_feedforward > 0.0) {
    const double kappa = LeaderCurvature(route, step.index, ahead);
    const double limit = options_.steering.max_turn_rate_radps;
    step.command.omega_radps = std::clamp(
        step.command.omega_radps + options_.leader_turn_feedforward * step.command.v_mps * kappa,
        -limit, limit);
  }
  MaybeLearn(image, low, route, recovered, &step);
  heading_offsets_.push_back(WrapAngle(
      odometry.theta_rad - route.images[static_cast<std::size_t>(step.index)]->odometry.theta_rad));
  while (static_cast<int>(heading_offsets_.size()) > options_.carry_on_heading_frames)
    heading_offsets_.pop_front();
  return step;
}

}  // namespace mapless::navigation

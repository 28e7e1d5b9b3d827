// The appearance-based route following experiments of Payá et al. (Section 5, Fig. 7-9) on the
// simulator: a leader teaches the route (incremental or batch PCA), a follower starts on the route
// or off it and follows it to the end, with Markov localization or the nearest projection alone,
// after the leader has finished or while it is still teaching (two robots in one world).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "mapless/eval/suite.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/navigation/appearance.h"
#include "mapless/route/appearance_store.h"
#include "mapless/sim/camera_faults.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {

// A route taught on the simulator and stored as `teach --method eigenspace` stores it, with the
// truth a run measures against: what a follower follows instead of a leader teaching first
// (EigenspaceRunOptions::taught; eval lifelong --method eigenspace).
struct TaughtAppearance {
  route::StoredAppearanceRoute stored;  // its learned views grow with each follow that learns
  std::vector<Pose2> leader_path;       // ground truth of the teach, every frame
  std::vector<Pose2> image_truth;       // ground truth at each route image
};

struct EigenspaceRunOptions {
  std::uint64_t seed = 1;
  // Follower start relative to the taught start, in the start's frame: x forward (negative =
  // behind), y to the left, theta counter-clockwise.
  Pose2 start_offset;
  bool concurrent = false;  // follow while the leader is still teaching
  int follower_starts_after_images =
      5;                      // concurrent: the leader's images before the follower starts
  double motion_noise = 0.0;  // follower motion noise fraction (both v and omega)
  // Metrics count after convergence: once the follower has driven convergence_m and come within
  // converged_lateral_m of the leader's path (a follower that starts off the route localizes
  // poorly until it is on it: Fig. 9 of the paper).
  double convergence_m = 3.0;
  double converged_lateral_m = 0.15;
  double arrive_tolerance_m = 0.6;  // success: arrived within this distance of the route end
  double timeout_factor = 3.0;      // give up after this many times the nominal duration
  // A stop that does not clear (an obstacle that stays, ground that cannot be checked) ends the
  // run after this long, as a robot file's safety.max_blocked_s does on a robot (0: never).
  double max_blocked_s = 60.0;
  std::vector<sim::CameraFaultWindow> camera_faults;  // the follower's camera (sim/camera_faults.h)
  navigation::AppearanceLeaderOptions leader;
  navigation::AppearanceFollowerOptions follower;
  // Follow this stored route (its learned views included) instead of teaching one first; not
  // with `concurrent`.
  const TaughtAppearance* taught = nullptr;
};

// Teaches `scenario`'s route as RunEigenspaceFollow's leader does (the scripted driver, clean),
// stored.
TaughtAppearance TeachAppearanceOnSimulator(const sim::Scenario& scenario,
                                            const EigenspaceRunOptions& options);

// The follower's simulated robot of a run that follows a finished route (see eval::SimSetup), and
// its timeout in simulated seconds: the same for RunEigenspaceFollow, `mapless follow` and
// `mapless sim serve --like follow`.
SimSetup FollowSimSetup(const sim::Scenario& scenario, const EigenspaceRunOptions& options);
double FollowTimeoutS(const sim::Scenario& scenario, const EigenspaceRunOptions& options);

struct EigenspaceRun {
  bool success = false;
  bool collided = false;
  std::string status;
  int route_images = 0;
  double final_error_m = 0.0;            // follower's end to the taught end
  double lateral_rms_m = 0.0;            // after convergence, to the leader's path
  double localization_within_one = 0.0;  // fraction of frames after convergence (±1 image)
  double nearest_within_one = 0.0;       // the same for the nearest projection alone
  int frames_after_convergence = 0;
  double convergence_distance_m = -1.0;  // driven before convergence (-1: never)
  int stops = 0;                         // frames in which the follower stood still and said why
  // The obstacle watch: times it stopped the follower, how many of those while an object added
  // at follow time (the scenario's repeat variant) stood in the world, and the smallest clearance
  // between the follower's footprint and such an object while it stood (+inf without one).
  int obstacle_stops = 0;
  int stops_at_added_object = 0;
  double min_clearance_m = std::numeric_limits<double>::infinity();
  std::vector<Pose2> leader_path;    // ground truth
  std::vector<Pose2> follower_path;  // ground truth
  // AppearanceFollowerOptions::learn: what the follow learned and the view each place was steered
  // by (navigation::ApplyAppearanceVisit).
  std::vector<navigation::LearnedAppearanceView> learned;
  std::vector<int> used_views;
};

// Called for every follower frame (for logs and debugging).
using EigenspaceObserver =
    std::function<void(const navigation::FollowerStep& step, const Pose2& truth)>;

EigenspaceRun RunEigenspaceFollow(const sim::Scenario& scenario,
                                  const EigenspaceRunOptions& options,
                                  const EigenspaceObserver& observer = {});

// One line of `mapless eval eigenspace` (also obstacle_box_office, on-route: the obstacle watch
// in the follower, issue 21).
struct EigenspaceEntry {
  std::string scenario;
  std::string experiment;  // on-route, off-route-left, off-route-right, batch-pca, no-markov,
                           // concurrent
};
std::vector<EigenspaceEntry> EigenspaceSuiteEntries();
EigenspaceRunOptions EigenspaceEntryOptions(const EigenspaceEntry& entry, std::uint64_t seed);

struct EigenspaceEntryResult : EntryResult {
  std::string experiment;
  double localization_within_one = 0.0;  // mean over runs (Markov or nearest, as the run used)
  double nearest_within_one = 0.0;       // mean over runs, nearest projection alone
  double lateral_rms_m_max = 0.0;        // worst run
  int stops = 0;                         // total stop frames over runs
  int learned = 0;                       // learn: views learned over the runs
};

// `first_run` (if set) observes every follower frame of the first run (for reports). `learn`
// (`eval eigenspace --learn`, issue 45): the runs follow one route, taught as the first run's
// leader teaches it, in turn, each arrived run's learned views written into it for the next (the
// concurrent entry teaches each run's route as without it).
EigenspaceEntryResult RunEigenspaceEntry(const EigenspaceEntry& entry, int runs, std::uint64_t seed,
                                         const EigenspaceObserver& first_run = {},
                                         bool learn = false);

}  // namespace mapless::eval

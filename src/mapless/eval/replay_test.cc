// A recorded run replays to the same decisions (issue 20): a repeat on the simulator, recorded
// through the recording link, played back open loop from the MCAP file through the same method and
// loop, decides exactly as the live run did, frame for frame.
#include <gtest/gtest.h>

#include <filesystem>

#include "mapless/eval/teach_repeat.h"
#include "mapless/recording/playback.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/methods.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {
namespace {

bool SameStep(const navigation::RepeatStep& a, const navigation::RepeatStep& b) {
  return a.status == b.status && a.destination == b.destination && a.matches == b.matches &&
         a.tracked == b.tracked && a.switched == b.switched &&
         a.switching.std_ratio == b.switching.std_ratio && a.switching.ed_px == b.switching.ed_px &&
         a.sloped.slope_x == b.sloped.slope_x && a.sloped.slope_y == b.sloped.slope_y &&
         a.command.v_mps == b.command.v_mps && a.command.omega_radps == b.command.omega_radps &&
         a.reason == b.reason;
}

TEST(Replay, ARecordedRepeatReplaysToTheSameDecisions) {
  const sim::Scenario scenario = sim::LoadScenario("table1_almost_straight");
  const TaughtRoute taught = TeachOnSimulator(scenario, navigation::TeachOptions{});
  const std::string path = ::testing::TempDir() + "mapless_replay_repeat.mcap";
  std::filesystem::remove(path);

  RepeatRunOptions options;
  options.seed = 7;
  std::vector<navigation::RepeatStep> live;
  std::vector<Timestamp> live_times;
  {
    recording::RunRecorderOptions rec_options;
    rec_options.camera_info = recording::CameraInfoOf(scenario.camera.model);
    recording::RunRecorder recorder(path, rec_options);
    options.wrap_link = [&](robot::RobotLink& inner) -> std::unique_ptr<robot::RobotLink> {
      return std::make_unique<recording::RecordingLink>(inner, recorder, "repeat");
    };
    const RepeatRun run =
        RepeatOnSimulator(scenario, taught, options,
                          [&](const Pose2&, const cv::Mat&, const navigation::RepeatStep& step) {
                            live.push_back(step);
                          });
    ASSERT_TRUE(run.success) << run.status;
  }  // the recorder closes the file

  robot::RepeatMethod method(taught.route, options.repeat);
  recording::PlaybackLink link(recording::OpenSource(path, {}));
  std::vector<navigation::RepeatStep> replayed;
  int odometry_frames = 0;
  const robot::LoopResult result =
      robot::RunLoop(method, link, robot::LoopOptions{},
                     [&](const robot::Observation& obs, const robot::Decision& decision) {
                       replayed.push_back(decision.DetailAs<robot::RepeatDetail>()->step);
                       odometry_frames += obs.odometry.has_value() ? 1 : 0;
                       return true;
                     });
  ASSERT_EQ(replayed.size(), live.size());
  int differing = 0;
  for (std::size_t i = 0; i < live.size(); ++i) {
    if (!SameStep(live[i], replayed[i])) {
      if (++differing <= 3) ADD_FAILURE() << "frame " << i << " decided differently";
    }
  }
  EXPECT_EQ(differing, 0);
  EXPECT_TRUE(result.finished) << result.reason;  // the replay completes the route too
  EXPECT_EQ(odometry_frames, static_cast<int>(live.size()));
}

}  // namespace
}  // namespace mapless::eval

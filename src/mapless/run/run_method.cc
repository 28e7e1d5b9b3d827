#include "mapless/run/run_method.h"

#include <memory>

#include "mapless/core/interrupt.h"
#include "mapless/recording/playback.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/status.h"

namespace mapless::run {

RunOutcome RunMethod(robot::Method& method, robot::RobotLink& link, const RunOptions& options) {
  std::unique_ptr<robot::RobotLink> recording;
  if (options.recorder)
    recording = std::make_unique<recording::RecordingLink>(link, *options.recorder, method.name());
  robot::RobotLink& recorded = recording ? *recording : link;
  const std::unique_ptr<robot::RobotLink> shown =
      options.live ? live::LiveWrapper(options.live)(recorded) : nullptr;
  robot::RobotLink& used = shown ? *shown : recorded;
  const std::function<bool()> interrupted =
      options.interrupted ? options.interrupted : [] { return InterruptRequested(); };
  RunOutcome outcome;
  int frame = 0;
  std::string last_said;
  outcome.loop = robot::RunLoop(
      method, used, options.loop,
      [&](const robot::Observation& obs, const robot::Decision& decision) {
        if (options.log) {
          nlohmann::json j = robot::StatusJson(method.name(), frame, obs, decision);
          if (options.more_fields) options.more_fields(&j);
          options.log(j);
        }
        ++frame;
        const bool driving = decision.state == robot::MethodState::kDriving;
        if (driving) ++outcome.driving_frames;
        if (!driving && !decision.reason.empty()) outcome.last_stop_reason = decision.reason;
        const std::string state =
            decision.status + (decision.reason.empty() ? "" : ": " + decision.reason);
        if (options.say && !driving && state != last_said)
          options.say(std::string(method.name()) + ": " + state);
        last_said = driving ? "" : state;
        return options.observer ? options.observer(obs, decision) : true;
      },
      interrupted);
  outcome.interrupted = interrupted();
  outcome.end_of_recording =
      !outcome.loop.finished && outcome.loop.reason == recording::kEndOfRecording;
  return outcome;
}

}  // namespace mapless::run

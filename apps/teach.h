// `mapless teach`: a route from the simulator, a recording, a camera or a robot, as keyframes for
// the funnel-lane repeat or as appearance route images for the eigenspace follower.
#pragma once

#include <string>

#include "recording_args.h"

namespace mapless::app {

struct TeachArgs {
  std::string source;
  std::string robot;
  std::string out;
  std::string method = "funnel";  // funnel | eigenspace
  bool overwrite = false;
  std::string detector = "orb";
  double fps = 10.0;
  recording::PlaybackOptions playback;  // a recording as the source
  RecordArgs record;                    // --record (simulator and robot teaches)
};

void Teach(const TeachArgs& t);

}  // namespace mapless::app

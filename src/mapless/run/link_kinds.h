// Opening a source from its text into a robot link: one table of link kinds, each with a test on
// the text and an opener. The standard table has a robot file (YAML, over the middleware it names:
// robot/middleware.h), a camera (`camera:N`) and the recordings (.mcap, .bag, a video, an image
// folder: recording/playback.h). A module that brings a new kind of link registers it here, with
// one Add; nothing else in the commands changes (the simulator's closed loop is a source of its
// own, sim_episode.h, because where a run starts on it depends on the method).
#pragma once

#include <functional>
#include <memory>
#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

#include "mapless/recording/playback.h"
#include "mapless/robot/link.h"
#include "mapless/robot/middleware.h"

namespace mapless::run {

// What a command asks of the link besides the source's text.
struct LinkRequest {
  std::string method = "teach";  // the method's name, in the status a robot link publishes
  // Frames the method needs; 0x0: as they come. A robot link resizes to it; a recording whose
  // frames differ is refused (`size_needed_by` says whose size it is: "the route R was taught at").
  cv::Size image_size;
  std::string size_needed_by;
  recording::PlaybackOptions playback;           // recordings, videos, image folders, cameras
  std::function<void(const std::string&)> warn;  // bad input heard on the way (may be empty)
};

struct LinkKind {
  std::string name;         // "robot", "camera", "recording", ...
  std::string description;  // for the list of kinds in errors and help: "a robot file (YAML)"
  std::function<bool(const std::string& text)> matches;
  std::function<std::unique_ptr<robot::RobotLink>(const std::string& text,
                                                  const LinkRequest& request)>
      open;
  // Frames come in real time from a device (a camera, a robot): Ctrl-C is the normal end of a
  // teach on it, and the run takes commands to a robot (`drives`) or not.
  bool live = false;
  bool drives = false;  // the link moves a robot: the run may record it (--record)
};

class LinkKinds {
 public:
  // Throws std::logic_error for a kind without a name, test or opener, or a name taken.
  void Add(LinkKind kind);
  // The first kind (in the order added) whose test accepts `text`; nullptr: none.
  const LinkKind* Find(const std::string& text) const;
  // As Find; throws InputError naming the text and the kinds there are.
  const LinkKind& For(const std::string& text) const;
  // The kind of that name (a command's --robot FILE is a robot file whatever its name); throws
  // std::logic_error when there is none.
  const LinkKind& Named(const std::string& name) const;
  std::unique_ptr<robot::RobotLink> Open(const std::string& text,
                                         const LinkRequest& request) const {
    return For(text).open(text, request);
  }
  std::vector<std::string> names() const;

 private:
  std::vector<LinkKind> kinds_;
};

// True for a robot file's name (.yaml or .yml, not sim:...).
bool IsRobotFile(const std::string& text);
// The input file of a source ("" for the simulator's built-in scenarios and cameras), for the
// commands' check that no output overwrites an input.
std::string SourceInput(const std::string& text);
bool IsSim(const std::string& text);

// The kinds of this build: robot files over `middlewares`, cameras and recordings.
LinkKinds StandardLinkKinds(const robot::MiddlewareRegistry& middlewares);

}  // namespace mapless::run

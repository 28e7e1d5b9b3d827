#include "mapless/run/link_kinds.h"

#include <stdexcept>

#include "mapless/core/check.h"
#include "mapless/io/frame_source.h"
#include "mapless/robot/robot_file.h"

namespace mapless::run {

namespace {

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string SizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

// A recording, video, image folder or camera played as a link; frames of another size than the
// method's are refused with the frame's name.
std::unique_ptr<robot::RobotLink> OpenPlayback(const std::string& text,
                                               const LinkRequest& request) {
  auto link =
      std::make_unique<recording::PlaybackLink>(recording::OpenSource(text, request.playback));
  if (request.image_size.area() > 0) {
    const cv::Size size = request.image_size;
    const std::string whose =
        request.size_needed_by.empty()
            ? request.method + " needs " + SizeText(size.width, size.height)
            : request.size_needed_by + " " + SizeText(size.width, size.height);
    link->set_frame_check([text, size, whose](const io::Frame& frame) {
      if (frame.image.cols != size.width || frame.image.rows != size.height)
        throw InputError(text + ": frame " + frame.name + " is " +
                         SizeText(frame.image.cols, frame.image.rows) + ", " + whose);
    });
  }
  return link;
}

}  // namespace

bool IsSim(const std::string& text) { return text.rfind("sim:", 0) == 0; }

bool IsRobotFile(const std::string& text) {
  return !IsSim(text) && (EndsWith(text, ".yaml") || EndsWith(text, ".yml"));
}

std::string SourceInput(const std::string& text) {
  if (IsSim(text)) {
    const std::string name = text.substr(4);
    return name.find('/') != std::string::npos || name.find(".y") != std::string::npos ? name : "";
  }
  return io::IsLiveCamera(text) ? "" : text;
}

void LinkKinds::Add(LinkKind kind) {
  if (kind.name.empty() || !kind.matches || !kind.open)
    throw std::logic_error("LinkKinds::Add: a kind needs a name, a test and an opener");
  for (const LinkKind& k : kinds_)
    if (k.name == kind.name) throw std::logic_error("LinkKinds::Add: " + kind.name + " twice");
  kinds_.push_back(std::move(kind));
}

const LinkKind* LinkKinds::Find(const std::string& text) const {
  for (const LinkKind& k : kinds_)
    if (k.matches(text)) return &k;
  return nullptr;
}

const LinkKind& LinkKinds::For(const std::string& text) const {
  if (const LinkKind* k = Find(text)) return *k;
  std::string kinds;
  for (const LinkKind& k : kinds_) kinds += (kinds.empty() ? "" : ", ") + k.description;
  throw InputError(text + ": not a source mapless can open (" + kinds + ")");
}

const LinkKind& LinkKinds::Named(const std::string& name) const {
  for (const LinkKind& k : kinds_)
    if (k.name == name) return k;
  throw std::logic_error("LinkKinds: no kind " + name);
}

std::vector<std::string> LinkKinds::names() const {
  std::vector<std::string> out;
  for (const LinkKind& k : kinds_) out.push_back(k.name);
  return out;
}

LinkKinds StandardLinkKinds(const robot::MiddlewareRegistry& middlewares) {
  LinkKinds kinds;
  LinkKind robot_kind;
  robot_kind.name = "robot";
  robot_kind.description = "a robot file (.yaml)";
  robot_kind.matches = IsRobotFile;
  robot_kind.live = true;
  robot_kind.drives = true;
  robot_kind.open = [&middlewares](const std::string& text, const LinkRequest& request) {
    const robot::RobotFile file = robot::LoadRobotFile(text);
    robot::Logger warn = request.warn;
    if (!warn) warn = [](const std::string&) {};
    return middlewares.For(file).open_link(file, request.image_size, request.method, warn);
  };
  kinds.Add(robot_kind);
  LinkKind camera;
  camera.name = "camera";
  camera.description = "camera:N";
  camera.matches = io::IsLiveCamera;
  camera.live = true;
  camera.open = OpenPlayback;
  kinds.Add(camera);
  LinkKind playback;
  playback.name = "recording";
  playback.description = "a recording (.mcap, .bag), a video or an image folder";
  playback.matches = [](const std::string& text) { return !text.empty() && !IsSim(text); };
  playback.open = OpenPlayback;
  kinds.Add(playback);
  return kinds;
}

}  // namespace mapless::run

#include "mapless/recording/playback.h"

#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/recording/mcap_source.h"
#include "mapless/recording/tum_poses.h"

namespace mapless::recording {

namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// --start, --loop and --rate over any source that can be opened again.
class PlaybackSource : public io::FrameSource {
 public:
  using Factory = std::function<std::unique_ptr<io::FrameSource>()>;
  PlaybackSource(Factory factory, const PlaybackOptions& options)
      : factory_(std::move(factory)), options_(options), source_(factory_()) {}

  bool Next(io::Frame* frame) override {
    while (true) {
      if (!source_) source_ = factory_();
      if (!source_->Next(frame)) {
        if (!options_.loop || played_in_pass_ == 0) return false;
        // The next pass goes on one frame period after this pass's last frame.
        next_pass_ns_ = last_out_ns_ + std::max<Timestamp>(last_gap_ns_, 1);
        source_.reset();
        pass_first_ns_ = kUnset;
        played_in_pass_ = 0;
        ++passes_;
        continue;
      }
      if (pass_first_ns_ == kUnset) pass_first_ns_ = frame->t_ns;
      if (ToSeconds(frame->t_ns - pass_first_ns_) < options_.start_s) continue;
      if (played_in_pass_ == 0 && passes_ > 0) offset_ns_ = next_pass_ns_ - frame->t_ns;
      frame->t_ns += offset_ns_;
      if (played_in_pass_ > 0) last_gap_ns_ = frame->t_ns - last_out_ns_;
      last_out_ns_ = frame->t_ns;
      ++played_in_pass_;
      Pace(frame->t_ns);
      return true;
    }
  }
  std::string Describe() const override { return source_ ? source_->Describe() : "(ended)"; }

 private:
  static constexpr Timestamp kUnset = std::numeric_limits<Timestamp>::min();

  void Pace(Timestamp t_ns) {
    if (options_.rate <= 0.0) return;
    const auto now = std::chrono::steady_clock::now();
    if (first_played_ns_ == kUnset) {
      first_played_ns_ = t_ns;
      wall_start_ = now;
      return;
    }
    const auto due =
        wall_start_ + std::chrono::nanoseconds(static_cast<std::int64_t>(
                          static_cast<double>(t_ns - first_played_ns_) / options_.rate));
    if (due > now) std::this_thread::sleep_until(due);
  }

  Factory factory_;
  PlaybackOptions options_;
  std::unique_ptr<io::FrameSource> source_;
  Timestamp offset_ns_ = 0;           // added to the source's times in this pass
  Timestamp pass_first_ns_ = kUnset;  // the source's time of the pass's first frame
  Timestamp last_out_ns_ = 0;
  Timestamp last_gap_ns_ = 0;
  Timestamp next_pass_ns_ = 0;
  int played_in_pass_ = 0;
  int passes_ = 0;
  Timestamp first_played_ns_ = kUnset;
  std::chrono::steady_clock::time_point wall_start_;
};

}  // namespace

void PlaybackOptions::Validate() const {
  if (!std::isfinite(rate) || (rate != 0.0 && (rate < 0.001 || rate > 1000.0)))
    throw InputError("--rate " + std::to_string(rate) +
                     ": expected 0 (as fast as used) or 0.001 to 1000");
  if (!std::isfinite(start_s) || start_s < 0.0)
    throw InputError("--start " + std::to_string(start_s) + ": expected seconds >= 0");
  if (!std::isfinite(fps) || fps < io::kMinFolderFps || fps > io::kMaxFolderFps)
    throw InputError("--fps " + std::to_string(fps) + ": out of range");
}

robot::LinkEvent PlaybackLink::Next() {
  robot::LinkEvent event;
  io::Frame frame;
  if (!source_->Next(&frame)) {
    event.type = robot::LinkEventType::kClosed;
    event.reason = kEndOfRecording;
    return event;
  }
  if (check_) check_(frame);
  now_ns_ = frame.t_ns;
  event.type = robot::LinkEventType::kFrame;
  event.observation.image = frame.image;
  event.observation.t_ns = frame.t_ns;
  event.observation.odometry = frame.odometry;
  return event;
}

bool CanReadBags() { return CanReadBagsImpl(); }

bool IsRecording(const std::string& spec) {
  return EndsWith(spec, ".mcap") || EndsWith(spec, ".bag");
}

std::unique_ptr<io::FrameSource> OpenSource(const std::string& spec,
                                            const PlaybackOptions& options) {
  options.Validate();
  PlaybackSource::Factory factory;
  if (!options.poses.empty() && (IsRecording(spec) || io::IsLiveCamera(spec))) {
    throw InputError("--poses " + options.poses + ": " + spec +
                     (IsRecording(spec) ? " has its own odometry topic (--odom-topic)"
                                        : " is a live camera; poses go with a video or an image "
                                          "folder"));
  }
  if (EndsWith(spec, ".mcap")) {
    factory = [spec, options] { return OpenMcapSource(spec, options.topic, options.odom_topic); };
  } else if (EndsWith(spec, ".bag")) {
    factory = [spec, options] { return OpenBagSource(spec, options.topic, options.odom_topic); };
  } else {
    if (!options.topic.empty())
      throw InputError("--topic " + options.topic + ": " + spec +
                       " is not a recording with topics (.mcap, .bag)");
    if (options.poses.empty()) {
      factory = [spec, options] { return io::OpenFrameSource(spec, options.fps); };
    } else {
      auto poses = std::make_shared<const std::vector<io::StampedPose>>(ReadPoses(options.poses));
      factory = [spec, options, poses] {
        return WithPoses(io::OpenFrameSource(spec, options.fps), *poses);
      };
    }
  }
  return std::make_unique<PlaybackSource>(std::move(factory), options);
}

}  // namespace mapless::recording

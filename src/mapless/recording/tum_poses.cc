#include "mapless/recording/tum_poses.h"

#include <cmath>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"

namespace mapless::recording {

namespace {

constexpr Timestamp kRoundingNs = 1'000'000;  // TUM times are written with microseconds

class PosesSource : public io::FrameSource {
 public:
  PosesSource(std::unique_ptr<io::FrameSource> source, std::vector<io::StampedPose> poses)
      : source_(std::move(source)), poses_(std::move(poses)) {}

  bool Next(io::Frame* frame) override {
    if (!source_->Next(frame)) return false;
    frame->t_ns += poses_.front().t_ns;
    while (next_ < poses_.size() && poses_[next_].t_ns <= frame->t_ns + kRoundingNs) ++next_;
    frame->odometry.reset();
    // next_ > 0 always: the first frame is at the first pose's time.
    if (next_ > 0 && frame->t_ns - poses_.back().t_ns <= FromSeconds(kPosesCoverS)) {
      frame->odometry = poses_[next_ - 1].pose;
    }
    return true;
  }
  std::string Describe() const override {
    return source_->Describe() + " with " + std::to_string(poses_.size()) + " poses";
  }

 private:
  std::unique_ptr<io::FrameSource> source_;
  std::vector<io::StampedPose> poses_;
  std::size_t next_ = 0;
};

}  // namespace

std::vector<io::StampedPose> ReadPoses(const std::string& path) {
  const std::string text = io::ReadFile(path, io::kMaxTrajectoryBytes);
  std::vector<io::StampedPose> poses = io::ParseTum(text, path);
  if (poses.empty()) throw InputError(path + ": no poses (TUM: timestamp tx ty tz qx qy qz qw)");
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const io::StampedPose& p = poses[i];
    if (!std::isfinite(p.pose.x_m) || !std::isfinite(p.pose.y_m) ||
        !std::isfinite(p.pose.theta_rad)) {
      throw InputError(path + ": pose " + std::to_string(i + 1) + " is not finite");
    }
    if (i > 0 && p.t_ns < poses[i - 1].t_ns) {
      throw InputError(path + ": pose " + std::to_string(i + 1) + " at " +
                       std::to_string(ToSeconds(p.t_ns)) + " s is earlier than the one before");
    }
  }
  return poses;
}

std::unique_ptr<io::FrameSource> WithPoses(std::unique_ptr<io::FrameSource> source,
                                           std::vector<io::StampedPose> poses) {
  MAPLESS_CHECK(!poses.empty(), "WithPoses: no poses");
  return std::make_unique<PosesSource>(std::move(source), std::move(poses));
}

}  // namespace mapless::recording

#include "mapless/run/leader_sink.h"

#include <memory>

#include "mapless/route/appearance_store.h"
#include "mapless/route/route_store.h"

namespace mapless::run {

void LeaderSink::Keyframe(const route::Keyframe& keyframe) {
  route::Keyframe numbered = keyframe;
  numbered.index = static_cast<int>(copy_.next_sequence()) - 1;  // record 0 is the header
  fleet::Record record = fleet::KeyframeRecord(numbered);
  Serve(std::move(record), std::move(numbered));
}

void LeaderSink::Image(const route::StoredAppearanceImage& image) {
  Serve(fleet::ImageRecord(image), std::nullopt, image.low);
}

void LeaderSink::Serve(fleet::Record record, std::optional<route::Keyframe> keyframe,
                       const cv::Mat& image_low) {
  record.sequence = copy_.next_sequence();
  copy_.ApplyOwn(record, std::move(keyframe), image_low);
  server_.Notify();
}

std::function<bool(const sim::DriveFrame&)> ResumeLeader(const fleet::RouteCopy& copy,
                                                         fleet::RouteKind kind, Teacher* teacher) {
  if (copy.next_sequence() == 0 || copy.complete()) return {};
  const int stored = static_cast<int>(copy.next_sequence()) - 1;  // record 0 is the header
  if (stored == 0) {
    teacher->Resume(0, nullptr, std::nullopt);
    return {};
  }
  if (kind == fleet::RouteKind::kEigenspace) {
    // The model as the interrupted leader had it.
    const route::StoredAppearanceRoute images = route::LoadAppearanceRoute(copy.dir());
    teacher->Resume(stored, &images, std::nullopt);
    const Pose2 last = images.images.back().odometry;
    auto rendering = std::make_shared<bool>(false);
    return [last, rendering](const sim::DriveFrame& f) {
      if (*rendering) return false;
      if (f.odometry.x_m == last.x_m && f.odometry.y_m == last.y_m &&
          f.odometry.theta_rad == last.theta_rad)
        *rendering = true;  // from the next frame on
      return true;
    };
  }
  // The last stored keyframe's time (read back from its file).
  const std::vector<fleet::Record> last = copy.RecordsFrom(copy.next_sequence() - 1, 1);
  const Timestamp last_t_ns = route::ParseKeyframe(last.at(0).parts.at(0), copy.dir()).t_ns;
  teacher->Resume(stored, nullptr, last_t_ns);
  return [last_t_ns](const sim::DriveFrame& f) { return f.t_ns < last_t_ns; };
}

}  // namespace mapless::run

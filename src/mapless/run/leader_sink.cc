#include "mapless/run/leader_sink.h"

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

}  // namespace mapless::run

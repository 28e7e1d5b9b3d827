#include "mapless/recording/mcap_source.h"

#include <map>
#include <optional>

#include "mapless/core/check.h"
#include "mapless/robot/camera_image.h"
#include "mapless/rosmsg/messages.h"

namespace mapless::recording {

namespace {

constexpr const char* kImage = "sensor_msgs/msg/Image";
constexpr const char* kCompressed = "sensor_msgs/msg/CompressedImage";
constexpr const char* kOdometry = "nav_msgs/msg/Odometry";

std::string TopicList(const std::vector<RecordedTopic>& topics, bool (*keep)(const std::string&)) {
  std::string s;
  for (const RecordedTopic& t : topics) {
    if (!keep(t.type)) continue;
    s += (s.empty() ? "" : ", ") + t.topic + " (" + t.type + ")";
  }
  return s.empty() ? "none" : s;
}

bool IsImageType(const std::string& type) { return type == kImage || type == kCompressed; }
bool IsOdometryType(const std::string& type) { return type == kOdometry; }
bool AnyType(const std::string&) { return true; }

// The topic to use: `wanted` (checked), or the only one of its kind.
const RecordedTopic* Choose(const std::vector<RecordedTopic>& topics, const std::string& wanted,
                            bool (*keep)(const std::string&), const std::string& name,
                            const char* kind, bool required) {
  if (!wanted.empty()) {
    for (const RecordedTopic& t : topics) {
      if (t.topic != wanted) continue;
      if (!keep(t.type))
        throw InputError(name + ": topic " + wanted + " is " + t.type + ", not " + kind);
      return &t;
    }
    throw InputError(name + ": no topic " + wanted + " (topics: " + TopicList(topics, AnyType) +
                     ")");
  }
  const RecordedTopic* found = nullptr;
  for (const RecordedTopic& t : topics) {
    if (!keep(t.type)) continue;
    if (found)
      throw InputError(name + ": several " + kind + " topics (" + TopicList(topics, keep) +
                       "); choose one with --topic");
    found = &t;
  }
  if (!found && required)
    throw InputError(name + ": no " + kind + " topic (topics: " + TopicList(topics, AnyType) + ")");
  return found;
}

class TopicFrames : public io::FrameSource {
 public:
  TopicFrames(std::unique_ptr<MessageStream> messages, const std::string& topic,
              const std::string& odom_topic)
      : messages_(std::move(messages)) {
    const std::vector<RecordedTopic>& topics = messages_->topics();
    image_ = Choose(topics, topic, IsImageType, messages_->name(), "camera image", true)->topic;
    if (odom_topic != "none") {
      const RecordedTopic* odom = Choose(topics, odom_topic, IsOdometryType, messages_->name(),
                                         "odometry (nav_msgs/msg/Odometry)", false);
      if (odom) odom_ = odom->topic;
    }
  }

  bool Next(io::Frame* frame) override {
    RecordedMessage m;
    if (held_) {
      m = *held_;
      m.data = held_data_;
      held_.reset();
    } else if (!NextImage(&m)) {
      return false;
    }
    const Timestamp t = DecodeFrame(m, frame);
    // Odometry may follow its frame in the file: read on to the next image, holding it.
    RecordedMessage ahead;
    if (NextImage(&ahead)) {
      held_data_.assign(ahead.data);
      held_ = ahead;
    }
    for (auto it = pending_odometry_.begin(); it != pending_odometry_.end() && it->first <= t;) {
      odometry_ = it->second;
      it = pending_odometry_.erase(it);
    }
    frame->odometry = odometry_;
    return true;
  }

  std::string Describe() const override { return messages_->name() + " " + image_; }

 private:
  static Timestamp Stamp(Timestamp header, Timestamp log) { return header != 0 ? header : log; }

  template <typename F>
  auto Decode(const RecordedMessage& m, F decode) {
    return Checked(m, [&] { return decode(m.data, m.wire); });
  }
  template <typename F>
  auto Checked(const RecordedMessage& m, F f) {
    try {
      return f();
    } catch (const InputError& e) {
      throw InputError(messages_->name() + ": " + m.topic->topic + " message at " +
                       std::to_string(ToSeconds(m.log_ns)) + " s: " + e.what());
    }
  }

  // The next message of the image topic; odometry on the way is kept for the frames.
  bool NextImage(RecordedMessage* m) {
    while (messages_->Next(m)) {
      if (!odom_.empty() && m->topic->topic == odom_) {
        const rosmsg::OdometryFields o = Decode(
            *m, [](std::string_view b, rosmsg::Wire w) { return rosmsg::DecodeOdometry(b, w); });
        pending_odometry_[Stamp(o.header.stamp_ns, m->log_ns)] = o.pose;
        continue;
      }
      if (m->topic->topic == image_) return true;
    }
    return false;
  }

  // The frame's grey image, name and time.
  Timestamp DecodeFrame(const RecordedMessage& m, io::Frame* frame) {
    Timestamp t = 0;
    if (m.topic->type == kImage) {
      const rosmsg::ImageFields im =
          Decode(m, [](std::string_view b, rosmsg::Wire w) { return rosmsg::DecodeImage(b, w); });
      t = Stamp(im.header.stamp_ns, m.log_ns);
      frame->image = Checked(m, [&] {
        return robot::GreyFromRaw(im.encoding, im.width, im.height, im.step, im.big_endian,
                                  im.data);
      });
    } else {
      const rosmsg::CompressedImageFields im = Decode(m, [](std::string_view b, rosmsg::Wire w) {
        return rosmsg::DecodeCompressedImage(b, w);
      });
      t = Stamp(im.header.stamp_ns, m.log_ns);
      frame->image = Checked(m, [&] { return robot::GreyFromCompressed(im.format, im.data); });
    }
    if (!size_.empty() && frame->image.size() != size_)
      throw InputError(messages_->name() + ": " + image_ + " frame " + std::to_string(count_) +
                       " is " + std::to_string(frame->image.cols) + "x" +
                       std::to_string(frame->image.rows) + ", the first was " +
                       std::to_string(size_.width) + "x" + std::to_string(size_.height));
    size_ = frame->image.size();
    frame->t_ns = t;
    frame->name = std::to_string(count_++);
    return t;
  }

  std::unique_ptr<MessageStream> messages_;
  std::string image_;
  std::string odom_;
  std::optional<RecordedMessage> held_;  // the next frame's message, read ahead
  std::string held_data_;
  std::map<Timestamp, Pose2> pending_odometry_;
  std::optional<Pose2> odometry_;
  cv::Size size_;
  int count_ = 0;
};

class McapMessages : public MessageStream {
 public:
  explicit McapMessages(const std::string& path)
      : reader_(path), topics_(McapTopics(reader_)), stream_(reader_) {
    for (std::size_t i = 0; i < topics_.size(); ++i) by_topic_[topics_[i].topic] = i;
  }
  const std::vector<RecordedTopic>& topics() const override { return topics_; }
  std::string name() const override { return reader_.path(); }
  bool Next(RecordedMessage* m) override {
    while (stream_.Next(&item_)) {
      const auto it = by_topic_.find(item_.channel->topic);
      if (it == by_topic_.end()) continue;  // a channel the summary did not list
      if (item_.channel->message_encoding != "cdr") continue;
      m->topic = &topics_[it->second];
      m->log_ns =
          static_cast<Timestamp>(std::min<std::uint64_t>(item_.message.log_time, INT64_MAX));
      m->data = item_.message.data;
      m->wire = rosmsg::Wire::kCdr;
      return true;
    }
    return false;
  }

 private:
  McapReader reader_;
  std::vector<RecordedTopic> topics_;
  std::map<std::string, std::size_t> by_topic_;
  McapMessageStream stream_;
  McapMessageStream::Item item_;
};

}  // namespace

std::unique_ptr<io::FrameSource> FramesFromMessages(std::unique_ptr<MessageStream> messages,
                                                    const std::string& topic,
                                                    const std::string& odom_topic) {
  return std::make_unique<TopicFrames>(std::move(messages), topic, odom_topic);
}

std::vector<RecordedTopic> McapTopics(McapReader& reader) {
  std::map<std::uint16_t, std::string> schema_names;
  std::map<std::string, std::string> topics;  // topic -> type, sorted by topic
  auto take = [&](std::uint8_t op, std::string_view body) {
    if (op == static_cast<std::uint8_t>(McapOp::kSchema)) {
      McapSchema s = ParseMcapSchema(body);
      schema_names[s.id] = s.name;
    } else if (op == static_cast<std::uint8_t>(McapOp::kChannel)) {
      const McapChannel c = ParseMcapChannel(body);
      const auto s = schema_names.find(c.schema_id);
      topics[c.topic] = s == schema_names.end() ? "" : s->second;
    }
  };
  // The footer is the 29 bytes before the closing magic; its summary_start leads to the summary.
  const std::string_view bytes = reader.bytes();
  constexpr std::size_t kFooterRecord = 1 + 8 + 20;
  bool from_summary = false;
  if (bytes.size() >= 2 * kMcapMagic.size() + kFooterRecord &&
      bytes.substr(bytes.size() - kMcapMagic.size()) == kMcapMagic) {
    const std::size_t footer_at = bytes.size() - kMcapMagic.size() - kFooterRecord;
    McapRecordCursor cursor(bytes.substr(footer_at, kFooterRecord), footer_at);
    std::uint8_t op = 0;
    std::string_view body;
    try {
      if (cursor.Next(&op, &body) && op == static_cast<std::uint8_t>(McapOp::kFooter)) {
        const McapFooter footer = ParseMcapFooter(body);
        if (footer.summary_start >= kMcapMagic.size() && footer.summary_start < footer_at) {
          McapRecordCursor summary(
              bytes.substr(footer.summary_start, footer_at - footer.summary_start),
              footer.summary_start);
          while (summary.Next(&op, &body)) take(op, body);
          from_summary = true;
        }
      }
    } catch (const InputError& e) {
      throw InputError(reader.path() + ": summary: " + e.what());
    }
  }
  if (!from_summary)
    reader.ForEachRecord(
        [&](std::uint8_t op, std::string_view body, std::uint64_t) { take(op, body); });
  std::vector<RecordedTopic> out;
  for (const auto& [topic, type] : topics) out.push_back({topic, type});
  return out;
}

std::unique_ptr<MessageStream> OpenMcapMessages(const std::string& path) {
  return std::make_unique<McapMessages>(path);
}

std::unique_ptr<io::FrameSource> OpenMcapSource(const std::string& path, const std::string& topic,
                                                const std::string& odom_topic) {
  return FramesFromMessages(std::make_unique<McapMessages>(path), topic, odom_topic);
}

}  // namespace mapless::recording

// ROS 1 bags through Debian's rosbag_storage (librosbag-storage-dev): the container (chunks
// uncompressed, bz2 or lz4, the index) is the library's; the message bodies are read by
// rosmsg/messages.h from the ROS 1 serialization, with every length checked. The library trusts
// the lengths in the file, so bag_check.h walks its structure first.
#include "mapless/core/check.h"
#include "mapless/recording/bag_check.h"
#include "mapless/recording/mcap_source.h"

#ifdef MAPLESS_HAVE_ROSBAG
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <map>
#include <optional>

#include "mapless/recording/bag_check.h"
#endif

namespace mapless::recording {

#ifdef MAPLESS_HAVE_ROSBAG
namespace {

// "sensor_msgs/Image" -> "sensor_msgs/msg/Image".
std::string Ros2Type(const std::string& ros1) {
  const auto slash = ros1.find('/');
  if (slash == std::string::npos) return ros1;
  return ros1.substr(0, slash) + "/msg/" + ros1.substr(slash + 1);
}

// A message body is refused above this before it is copied (a 4K colour image is 25 MB).
constexpr std::uint32_t kMaxBagMessageBytes = 256u << 20;

class BagMessages : public MessageStream {
 public:
  explicit BagMessages(const std::string& path) : path_(path) {
    CheckBagStructure(path);  // the library trusts the file's lengths
    try {
      bag_.open(path, rosbag::bagmode::Read);
      view_.emplace(bag_);
      std::map<std::string, std::string> topics;
      for (const rosbag::ConnectionInfo* c : view_->getConnections())
        topics[c->topic] = Ros2Type(c->datatype);
      for (const auto& [topic, type] : topics) topics_.push_back({topic, type});
      it_ = view_->begin();
    } catch (const std::exception& e) {  // rosbag::BagException and the library's others
      throw InputError(path + ": not a readable ROS 1 bag: " + e.what());
    }
  }
  const std::vector<RecordedTopic>& topics() const override { return topics_; }
  std::string name() const override { return path_; }

  bool Next(RecordedMessage* m) override {
    try {
      if (it_ == view_->end()) return false;
      const rosbag::MessageInstance& instance = *it_;
      const std::uint32_t size = instance.size();
      if (size > kMaxBagMessageBytes)
        throw InputError(path_ + ": a message of " + std::to_string(size) + " bytes on " +
                         instance.getTopic() + " (at most " + std::to_string(kMaxBagMessageBytes) +
                         ")");
      buffer_.resize(size);
      ros::serialization::OStream stream(reinterpret_cast<std::uint8_t*>(buffer_.data()), size);
      instance.write(stream);
      m->topic = nullptr;
      for (const RecordedTopic& t : topics_)
        if (t.topic == instance.getTopic()) m->topic = &t;
      if (!m->topic) throw InputError(path_ + ": a message on an unknown topic");
      m->log_ns = static_cast<Timestamp>(instance.getTime().toNSec());
      m->data = buffer_;
      m->wire = rosmsg::Wire::kRos1;
      ++it_;
      return true;
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError(path_ + ": " + e.what());
    }
  }

 private:
  std::string path_;
  rosbag::Bag bag_;
  std::optional<rosbag::View> view_;
  rosbag::View::iterator it_;
  std::vector<RecordedTopic> topics_;
  std::string buffer_;
};

}  // namespace

bool CanReadBagsImpl() { return true; }

std::unique_ptr<io::FrameSource> OpenBagSource(const std::string& path, const std::string& topic,
                                               const std::string& odom_topic) {
  return FramesFromMessages(std::make_unique<BagMessages>(path), topic, odom_topic);
}

std::unique_ptr<MessageStream> OpenBagMessages(const std::string& path) {
  return std::make_unique<BagMessages>(path);
}

#else

bool CanReadBagsImpl() { return false; }

void CheckBagStructure(const std::string& path) {
  throw InputError(path + ": ROS 1 bags need mapless built with librosbag-storage-dev");
}

std::unique_ptr<io::FrameSource> OpenBagSource(const std::string& path, const std::string&,
                                               const std::string&) {
  throw InputError(path +
                   ": ROS 1 bags need mapless built with librosbag-storage-dev "
                   "(scripts/setup.sh --ros, then build again)");
}

std::unique_ptr<MessageStream> OpenBagMessages(const std::string& path) {
  OpenBagSource(path, "", "");
  return nullptr;
}

#endif

}  // namespace mapless::recording

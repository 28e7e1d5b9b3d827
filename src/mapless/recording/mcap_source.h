// The frames of a recording's image topic, decoded to grey, with the odometry of the recording's
// odometry topic at each frame: the sources behind playback.h. The containers (MCAP, ROS 1 bag)
// give messages; what is done with them is shared.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mapless/io/frame_source.h"
#include "mapless/recording/mcap_reader.h"
#include "mapless/rosmsg/wire.h"

namespace mapless::recording {

// A topic and its type, in ROS 2 form ("sensor_msgs/msg/Image"; ROS 1 types are renamed).
struct RecordedTopic {
  std::string topic;
  std::string type;
};

struct RecordedMessage {
  const RecordedTopic* topic = nullptr;
  Timestamp log_ns = 0;
  std::string_view data;  // valid until the next message
  rosmsg::Wire wire = rosmsg::Wire::kCdr;
};

class MessageStream {
 public:
  virtual ~MessageStream() = default;
  virtual const std::vector<RecordedTopic>& topics() const = 0;
  virtual bool Next(RecordedMessage* message) = 0;
  virtual std::string name() const = 0;
};

// Frames from `messages`: the image topic `topic` ("": the only one), odometry from `odom_topic`
// ("": the only one if any, "none": none). The frame time is the header stamp (the log time when
// the stamp is zero); a frame carries the newest odometry not later than it.
std::unique_ptr<io::FrameSource> FramesFromMessages(std::unique_ptr<MessageStream> messages,
                                                    const std::string& topic,
                                                    const std::string& odom_topic);

// The channels (with their schemas' names as types) of an MCAP file: from its summary when it has
// one, else from every record.
std::vector<RecordedTopic> McapTopics(McapReader& reader);

std::unique_ptr<io::FrameSource> OpenMcapSource(const std::string& path, const std::string& topic,
                                                const std::string& odom_topic);
// The messages of an MCAP file or of a ROS 1 bag (tests, `mapless recording info`, fuzzing).
std::unique_ptr<MessageStream> OpenMcapMessages(const std::string& path);
// Throws InputError when mapless was built without ROS 1 bags.
std::unique_ptr<MessageStream> OpenBagMessages(const std::string& path);
bool CanReadBagsImpl();
// Throws InputError when mapless was built without ROS 1 bags.
std::unique_ptr<io::FrameSource> OpenBagSource(const std::string& path, const std::string& topic,
                                               const std::string& odom_topic);

}  // namespace mapless::recording

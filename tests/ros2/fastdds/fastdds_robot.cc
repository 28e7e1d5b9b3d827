// A real ROS 2 middleware on the other end (issue 40): an eProsima Fast DDS 2.9 participant, with
// types fastddsgen compiled from the ROS 2 message definitions (ros2_types.idl), between
// `mapless sim serve` (a simulated robot in namespace /sim) and `mapless repeat --robot` (the
// method, no namespace). It is started after both, and is the robot for the method: it relays
// /sim/camera/image_raw to /camera/image_raw and /sim/odom to /odom (mapless writes, Fast DDS
// reads; Fast DDS writes, mapless reads), and /cmd_vel back to /sim/cmd_vel; it reads
// /mapless/status and /mapless/debug_image, and presses the e-stop (/mapless/estop) once the robot
// is driven. Checks, as one JSON line, exit 0 when all hold:
//   - discovery: the first frame from sim serve and the first command from repeat within
//     MAX_DISCOVERY_S of this participant's start (mapless must see a newcomer quickly);
//   - every type: Image (mono8 and the bgr8 debug image), Odometry, Twist, String, Bool decoded
//     and well-formed in both directions; sim serve moved as the relayed commands said;
//   - cmd_vel at most the camera rate while driving; during a 1 s e-stop only zeros and at most
//     MAX_STOP_PER_S of them; driving again after the release.
//   fastdds_robot SECONDS MAX_DISCOVERY_S MAX_STOP_PER_S     (ROS_DOMAIN_ID from the environment)
// A second mode, `fastdds_robot lockstep SECONDS`, relays a lockstep simulation under
// use_sim_time: the clock and JPEG CompressedImages (see Lockstep()).
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "ros2_typesPubSubTypes.h"

namespace {

using namespace eprosima::fastdds::dds;  // NOLINT: a test program
using Clock = std::chrono::steady_clock;
using Image = sensor_msgs::msg::dds_::Image_;
using Odometry = nav_msgs::msg::dds_::Odometry_;
using Twist = geometry_msgs::msg::dds_::Twist_;
using RosString = std_msgs::msg::dds_::String_;
using Bool = std_msgs::msg::dds_::Bool_;

const Clock::time_point g_start = Clock::now();
double Since() { return std::chrono::duration<double>(Clock::now() - g_start).count(); }

std::mutex g_mutex;
struct Counts {
  int sim_frames = 0, bad_sim_frames = 0;
  double first_sim_frame_s = -1;
  int sim_odometry = 0;
  double first_x = NAN, first_y = NAN, last_x = NAN, last_y = NAN;
  int commands = 0, nonzero = 0;
  double first_command_s = -1;
  bool estop = false, estop_held = false, released = false;
  int during_estop = 0, nonzero_during_estop = 0, nonzero_after_release = 0;
  int statuses = 0, good_statuses = 0, debug_images = 0, good_debug_images = 0;
} g;

// A reader whose samples go to `on`: takes every sample waiting.
template <typename T>
class Listener : public DataReaderListener {
 public:
  explicit Listener(std::function<void(const T&)> on) : on_(std::move(on)) {}
  void on_data_available(DataReader* reader) override {
    T sample;
    SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) on_(sample);
  }

 private:
  std::function<void(const T&)> on_;
};

struct Node {
  DomainParticipant* participant = nullptr;
  Publisher* publisher = nullptr;
  Subscriber* subscriber = nullptr;

  explicit Node(int domain) {
    DomainParticipantQos qos;
    qos.name("fastdds_robot");
    if (std::getenv("FASTDDS_ROBOT_DEFAULT_QOS") != nullptr) {
      // Fast DDS as a ROS 2 node has it out of the box (multicast discovery, every interface).
      participant = DomainParticipantFactory::get_instance()->create_participant(domain, qos);
      if (participant == nullptr) throw std::runtime_error("cannot create the participant");
      publisher = participant->create_publisher(PUBLISHER_QOS_DEFAULT);
      subscriber = participant->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
      return;
    }
    // Loopback only, as ROS_LOCALHOST_ONLY asks: UDP on 127.0.0.1.
    qos.transport().use_builtin_transports = false;
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
    qos.transport().user_transports.push_back(udp);
    eprosima::fastrtps::rtps::Locator_t peer;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, 127, 0, 0, 1);
    // As rmw_fastrtps sets a localhost-only node up: discovery by multicast (unheard by mapless,
    // which waits for its own next announcement to find the newcomer: the hard case); with
    // FASTDDS_ROBOT_UNICAST_PEERS, loopback unicast peers as well.
    if (std::getenv("FASTDDS_ROBOT_UNICAST_PEERS") != nullptr)
      qos.wire_protocol().builtin.initialPeersList.push_back(peer);
    qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod =
        eprosima::fastrtps::Duration_t(1, 0);
    participant = DomainParticipantFactory::get_instance()->create_participant(domain, qos);
    if (participant == nullptr) throw std::runtime_error("cannot create the participant");
    publisher = participant->create_publisher(PUBLISHER_QOS_DEFAULT);
    subscriber = participant->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  }

  Topic* MakeTopic(const std::string& ros_name, TopicDataType* type) {
    TypeSupport support(type);
    support.register_type(participant);
    return participant->create_topic("rt" + ros_name, support.get_type_name(), TOPIC_QOS_DEFAULT);
  }
  // ROS 2's QoS: sensor data best effort, the default profile reliable; volatile, keep last.
  DataWriter* Writer(const std::string& ros_name, TopicDataType* type, bool reliable) {
    DataWriterQos qos = DATAWRITER_QOS_DEFAULT;
    qos.reliability().kind = reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
    qos.durability().kind = VOLATILE_DURABILITY_QOS;
    qos.history().kind = KEEP_LAST_HISTORY_QOS;
    qos.history().depth = reliable ? 10 : 5;
    qos.data_sharing().off();  // nothing left in /dev/shm by a test that ends with _Exit
    return publisher->create_datawriter(MakeTopic(ros_name, type), qos);
  }
  DataReader* Reader(const std::string& ros_name, TopicDataType* type, bool reliable,
                     DataReaderListener* listener) {
    DataReaderQos qos = DATAREADER_QOS_DEFAULT;
    qos.reliability().kind = reliable ? RELIABLE_RELIABILITY_QOS : BEST_EFFORT_RELIABILITY_QOS;
    qos.durability().kind = VOLATILE_DURABILITY_QOS;
    qos.history().kind = KEEP_LAST_HISTORY_QOS;
    qos.history().depth = 10;
    qos.data_sharing().off();
    return subscriber->create_datareader(MakeTopic(ros_name, type), qos, listener);
  }
};

bool WellFormed(const Image& m, const char* encoding, int channels) {
  return m.encoding() == encoding && m.width() >= 32 && m.height() >= 24 &&
         m.step() == m.width() * static_cast<std::uint32_t>(channels) &&
         m.data().size() == static_cast<std::size_t>(m.step()) * m.height();
}

// The simulated robot's odometry: counted, its first and last positions kept (how far it moved),
// and passed on to the method.
void RelayOdometry(const Odometry& m, DataWriter* to) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    ++g.sim_odometry;
    const double x = m.pose().pose().position().x(), y = m.pose().pose().position().y();
    if (std::isnan(g.first_x)) g.first_x = x, g.first_y = y;
    g.last_x = x;
    g.last_y = y;
  }
  Odometry copy = m;
  to->write(&copy);
}

bool Wait(double seconds, const std::function<bool()>& done) {
  const auto until = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < until) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (done()) return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  return done();
}

}  // namespace

// Lockstep under use_sim_time: sim serve publishes /clock and JPEG frames
// (/sim/camera/image_raw/compressed) and waits for each frame's command; the node relays the
// compressed frames and the odometry to the method (use_sim_time, compressed camera), and the
// commands and the status back (sim serve starts when a method's status and commands reach it).
// It reads the clock as the method does (one /clock for all: relaying it would echo). Checks the
// clock (mapless writes, Fast DDS reads) and the compressed frames both ways, and that the robot
// was driven and moved.
int Lockstep(double seconds) {
  const char* domain_text = std::getenv("ROS_DOMAIN_ID");
  Node node(domain_text ? std::atoi(domain_text) : 0);
  using Compressed = sensor_msgs::msg::dds_::CompressedImage_;
  using RosClock = rosgraph_msgs::msg::dds_::Clock_;
  DataWriter* camera = node.Writer("/camera/image_raw/compressed",
                                   new sensor_msgs::msg::dds_::CompressedImage_PubSubType, false);
  DataWriter* sim_status =
      node.Writer("/sim/mapless/status", new std_msgs::msg::dds_::String_PubSubType, true);
  DataWriter* odom = node.Writer("/odom", new nav_msgs::msg::dds_::Odometry_PubSubType, false);
  DataWriter* sim_cmd =
      node.Writer("/sim/cmd_vel", new geometry_msgs::msg::dds_::Twist_PubSubType, true);
  int frames = 0, bad_frames = 0, clocks = 0, clock_backwards = 0;
  double last_clock = -1;
  Listener<Compressed> on_frame([&](const Compressed& m) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      ++frames;
      const auto& d = m.data();
      const bool jpeg = d.size() > 4 && d[0] == 0xff && d[1] == 0xd8;
      if (m.format().find("jpeg") == std::string::npos || !jpeg) ++bad_frames;
    }
    Compressed copy = m;
    camera->write(&copy);
  });
  Listener<RosClock> on_clock([&](const RosClock& c) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      ++clocks;
      const double t = c.clock().sec() + 1e-9 * c.clock().nanosec();
      if (t < last_clock) ++clock_backwards;
      last_clock = t;
    }
  });
  Listener<Odometry> on_odom([&](const Odometry& m) { RelayOdometry(m, odom); });
  Listener<Twist> on_command([&](const Twist& t) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      ++g.commands;
      if (t.linear().x() != 0.0 || t.angular().z() != 0.0) ++g.nonzero;
    }
    Twist copy = t;
    sim_cmd->write(&copy);
  });
  node.Reader("/sim/camera/image_raw/compressed",
              new sensor_msgs::msg::dds_::CompressedImage_PubSubType, false, &on_frame);
  // The clock is one topic for all (/clock): read here from sim serve, as the method reads it.
  node.Reader("/clock", new rosgraph_msgs::msg::dds_::Clock_PubSubType, false, &on_clock);
  Listener<RosString> on_status([&](const RosString& m) {
    RosString copy = m;
    sim_status->write(&copy);
  });
  node.Reader("/mapless/status", new std_msgs::msg::dds_::String_PubSubType, true, &on_status);
  node.Reader("/sim/odom", new nav_msgs::msg::dds_::Odometry_PubSubType, false, &on_odom);
  node.Reader("/cmd_vel", new geometry_msgs::msg::dds_::Twist_PubSubType, true, &on_command);
  const bool driven = Wait(seconds, [] { return g.nonzero >= 30; });
  // Debug images are best effort, 230 KB each: on a loaded machine the first may take a while.
  Wait(5.0, [] { return g.debug_images > 0; });
  std::lock_guard<std::mutex> lock(g_mutex);
  const double moved = std::hypot(g.last_x - g.first_x, g.last_y - g.first_y);
  const bool ok = driven && frames >= 30 && bad_frames == 0 && clocks >= 30 &&
                  clock_backwards == 0 && moved > 0.1;
  std::printf(
      "{\"mode\": \"lockstep\", \"compressed_frames\": %d, \"bad_frames\": %d, \"clocks\": %d, "
      "\"clock_backwards\": %d, \"commands\": %d, \"nonzero\": %d, \"moved_m\": %.2f, \"ok\": "
      "%s}\n",
      frames, bad_frames, clocks, clock_backwards, g.commands, g.nonzero, moved,
      ok ? "true" : "false");
  std::fflush(stdout);
  std::_Exit(ok ? 0 : 1);
}

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "lockstep") return Lockstep(std::atof(argv[2]));
  if (argc != 4) {
    std::fprintf(stderr,
                 "usage: fastdds_robot SECONDS MAX_DISCOVERY_S MAX_STOP_PER_S\n"
                 "       fastdds_robot lockstep SECONDS\n");
    return 2;
  }
  const double seconds = std::atof(argv[1]);
  const double max_discovery_s = std::atof(argv[2]);
  const double max_stop_hz = std::atof(argv[3]);
  const char* domain_text = std::getenv("ROS_DOMAIN_ID");
  Node node(domain_text ? std::atoi(domain_text) : 0);

  DataWriter* camera =
      node.Writer("/camera/image_raw", new sensor_msgs::msg::dds_::Image_PubSubType, false);
  DataWriter* odom = node.Writer("/odom", new nav_msgs::msg::dds_::Odometry_PubSubType, false);
  DataWriter* sim_cmd =
      node.Writer("/sim/cmd_vel", new geometry_msgs::msg::dds_::Twist_PubSubType, true);
  DataWriter* estop = node.Writer("/mapless/estop", new std_msgs::msg::dds_::Bool_PubSubType, true);

  Listener<Image> on_sim_frame([&](const Image& m) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      ++g.sim_frames;
      if (!WellFormed(m, "mono8", 1)) ++g.bad_sim_frames;
      if (g.first_sim_frame_s < 0) g.first_sim_frame_s = Since();
    }
    Image copy = m;
    camera->write(&copy);
  });
  Listener<Odometry> on_sim_odom([&](const Odometry& m) { RelayOdometry(m, odom); });
  Listener<Twist> on_command([&](const Twist& t) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      const bool zero = t.linear().x() == 0.0 && t.angular().z() == 0.0;
      ++g.commands;
      if (g.first_command_s < 0) g.first_command_s = Since();
      if (!zero) ++g.nonzero;
      // The e-stop holds from the first zero after it was pressed (a command decided on an
      // earlier frame may still be on its way); from then on only zeros.
      if (g.estop && !g.released && zero) g.estop_held = true;
      if (g.estop_held && !g.released) {
        ++g.during_estop;
        if (!zero) ++g.nonzero_during_estop;
      }
      if (g.released && !zero) ++g.nonzero_after_release;
    }
    Twist copy = t;
    sim_cmd->write(&copy);
  });
  Listener<RosString> on_status([](const RosString& s) {
    std::lock_guard<std::mutex> lock(g_mutex);
    ++g.statuses;
    const std::string& t = s.data();
    if (t.size() > 2 && t.front() == '{' && t.back() == '}' &&
        t.find("\"method\":\"repeat\"") != std::string::npos)
      ++g.good_statuses;
  });
  Listener<Image> on_debug([](const Image& m) {
    std::lock_guard<std::mutex> lock(g_mutex);
    ++g.debug_images;
    if (WellFormed(m, "bgr8", 3)) ++g.good_debug_images;
  });
  node.Reader("/sim/camera/image_raw", new sensor_msgs::msg::dds_::Image_PubSubType, false,
              &on_sim_frame);
  node.Reader("/sim/odom", new nav_msgs::msg::dds_::Odometry_PubSubType, false, &on_sim_odom);
  node.Reader("/cmd_vel", new geometry_msgs::msg::dds_::Twist_PubSubType, true, &on_command);
  node.Reader("/mapless/status", new std_msgs::msg::dds_::String_PubSubType, true, &on_status);
  node.Reader("/mapless/debug_image", new sensor_msgs::msg::dds_::Image_PubSubType, false,
              &on_debug);

  std::string error;
  double frames_per_s = 0, commands_per_s = 0, stop_per_s = 0;
  if (!Wait(seconds, [] { return g.nonzero >= 10; })) {
    error = "the robot was never driven";
  } else {
    // Driving: commands against frames over 2 s.
    int f0, c0;
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      f0 = g.sim_frames;
      c0 = g.commands;
    }
    std::this_thread::sleep_for(std::chrono::seconds(2));
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      frames_per_s = (g.sim_frames - f0) / 2.0;
      commands_per_s = (g.commands - c0) / 2.0;
      g.estop = true;
    }
    Bool on;
    on.data(true);
    estop->write(&on);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    int held_from;
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      held_from = g.during_estop;
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      stop_per_s = g.during_estop - held_from;
      g.released = true;
    }
    Bool off;
    off.data(false);
    estop->write(&off);
    if (!Wait(5.0, [] { return g.nonzero_after_release > 0; }))
      error = "not driven again after the e-stop was released";
  }
  // Debug images are best effort, 230 KB each: on a loaded machine the first may take a while.
  Wait(5.0, [] { return g.debug_images > 0; });
  std::lock_guard<std::mutex> lock(g_mutex);
  const double moved = std::hypot(g.last_x - g.first_x, g.last_y - g.first_y);
  const bool discovery = g.first_sim_frame_s >= 0 && g.first_sim_frame_s <= max_discovery_s &&
                         g.first_command_s >= 0 && g.first_command_s <= max_discovery_s;
  const bool types = g.sim_frames > 0 && g.bad_sim_frames == 0 && g.sim_odometry > 0 &&
                     g.nonzero > 0 && g.good_statuses >= 10 && g.good_statuses == g.statuses &&
                     // best effort, 230 KB each: a loaded machine loses some
                     g.good_debug_images >= 1 && g.good_debug_images == g.debug_images &&
                     moved > 0.1;
  // Counted over the same 2 s, commands and the frames they answer differ by the one or two
  // in flight at either end.
  const bool rates = commands_per_s <= frames_per_s + 1.0 && g.nonzero_during_estop == 0 &&
                     g.during_estop > 0 && stop_per_s <= max_stop_hz;
  std::printf(
      "{\"first_sim_frame_s\": %.2f, \"first_command_s\": %.2f, \"sim_frames\": %d, "
      "\"bad_sim_frames\": %d, \"sim_odometry\": %d, \"moved_m\": %.2f, \"commands\": %d, "
      "\"statuses\": %d, \"good_statuses\": %d, \"debug_images\": %d, \"good_debug_images\": %d, "
      "\"frames_per_s\": %.1f, \"commands_per_s\": %.1f, \"estop_commands_per_s\": %.0f, "
      "\"nonzero_during_estop\": %d, \"resumed\": %s, \"discovery\": %s, \"types\": %s, "
      "\"rates\": %s%s%s%s}\n",
      g.first_sim_frame_s, g.first_command_s, g.sim_frames, g.bad_sim_frames, g.sim_odometry, moved,
      g.commands, g.statuses, g.good_statuses, g.debug_images, g.good_debug_images, frames_per_s,
      commands_per_s, stop_per_s, g.nonzero_during_estop,
      g.nonzero_after_release > 0 ? "true" : "false", discovery ? "true" : "false",
      types ? "true" : "false", rates ? "true" : "false", error.empty() ? "" : ", \"error\": \"",
      error.c_str(), error.empty() ? "" : "\"");
  std::fflush(stdout);
  std::_Exit(error.empty() && discovery && types && rates ? 0 : 1);  // no teardown under way
}

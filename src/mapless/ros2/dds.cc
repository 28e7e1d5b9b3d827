#include "mapless/ros2/dds.h"

#include <cstdlib>
#include <mutex>
#include <stdexcept>

#include "mapless/core/check.h"
#include "mapless/ros2/type_hash.h"

namespace mapless::ros2 {

namespace {

std::string Env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

// Discovery and data on loopback only, as rmw_cyclonedds does for ROS_LOCALHOST_ONLY: unicast to
// the local participant ports (no multicast on `lo`). A node that starts later and announces
// itself only by multicast (Fast DDS's default) hears of mapless when mapless next announces
// itself to those ports: twice a second here (Cyclone's default waited 6-9 s; issue 40), 66 small
// packets a second on loopback.
constexpr const char* kLocalhostConfig =
    "<CycloneDDS><Domain><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/>"
    "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
    "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>32"
    "</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers>"
    "<SPDPInterval>500ms</SPDPInterval></Discovery></Domain></CycloneDDS>";

// Input from the network is bounded: a sample larger than this (a 4096x4096 rgb8 image is 48 MiB)
// is dropped by Cyclone before it is delivered.
constexpr const char* kBoundsConfig =
    "<CycloneDDS><Domain><Internal><MaxSampleSize>64MiB</MaxSampleSize></Internal></Domain>"
    "</CycloneDDS>";

bool LocalhostOnly() {
  const std::string range = Env("ROS_AUTOMATIC_DISCOVERY_RANGE");
  return Env("ROS_LOCALHOST_ONLY") == "1" || range == "LOCALHOST" || range == "OFF";
}

std::string Error(const std::string& what, dds_return_t rc) {
  return what + ": " + dds_strretcode(rc);
}

struct ParticipantHolder {
  std::mutex mutex;
  dds_entity_t participant = 0;
  ~ParticipantHolder() {
    if (participant > 0) dds_delete(participant);
  }
};

ParticipantHolder& Holder() {
  static ParticipantHolder holder;
  return holder;
}

dds_qos_t* MakeQos(Qos kind, const std::string& ros_type) {
  dds_qos_t* qos = dds_create_qos();
  switch (kind) {
    case Qos::kSensorData:
      dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5);
      break;
    case Qos::kDefault:
      dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
      break;
    case Qos::kClock:
      dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
      break;
  }
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  // ROS 2 samples are plain CDR (XCDR1); a reader also takes XCDR2 from writers that offer only it.
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos, 1, &xcdr1);
  const std::string user_data = "typehash=" + TypeHash(ros_type) + ";";
  dds_qset_userdata(qos, user_data.data(), user_data.size());
  return qos;
}

dds_entity_t Topic(const dds_topic_descriptor_t* desc, const std::string& ros_name) {
  const std::string name = DdsTopicName(ros_name);
  const dds_entity_t topic = dds_create_topic(Participant(), desc, name.c_str(), nullptr, nullptr);
  if (topic < 0) throw std::runtime_error(Error("DDS topic " + name, topic));
  return topic;
}

}  // namespace

int DomainId() {
  const std::string text = Env("ROS_DOMAIN_ID");
  if (text.empty()) return 0;
  char* end = nullptr;
  const long id = std::strtol(text.c_str(), &end, 10);
  if (*end != '\0' || id < 0 || id > 232)
    throw InputError("ROS_DOMAIN_ID=" + text + ": must be a whole number from 0 to 232");
  return static_cast<int>(id);
}

std::string DdsTopicName(const std::string& ros_name) {
  return "rt" + (ros_name.empty() || ros_name[0] != '/' ? "/" + ros_name : ros_name);
}

dds_entity_t Participant() {
  ParticipantHolder& h = Holder();
  std::lock_guard<std::mutex> lock(h.mutex);
  if (h.participant > 0) return h.participant;
  const int domain = DomainId();
  // CYCLONEDDS_URI first, then what ROS's environment asks for (later fragments override).
  std::string config = Env("CYCLONEDDS_URI");
  if (!config.empty()) config += ",";
  config += kBoundsConfig;
  if (LocalhostOnly()) config += std::string(",") + kLocalhostConfig;
  const dds_entity_t d = dds_create_domain(static_cast<dds_domainid_t>(domain), config.c_str());
  if (d < 0 && d != DDS_RETCODE_PRECONDITION_NOT_MET)  // not met: the domain exists already
    throw std::runtime_error(Error("DDS domain " + std::to_string(domain) +
                                       " (check CYCLONEDDS_URI and the network interfaces)",
                                   d));
  dds_qos_t* qos = dds_create_qos();
  const std::string enclave = "enclave=/;";  // as rmw sets it
  dds_qset_userdata(qos, enclave.data(), enclave.size());
  const dds_entity_t p = dds_create_participant(static_cast<dds_domainid_t>(domain), qos, nullptr);
  dds_delete_qos(qos);
  if (p < 0) throw std::runtime_error(Error("DDS participant", p));
  h.participant = p;
  return p;
}

dds_entity_t MakeWriter(const dds_topic_descriptor_t* desc, const std::string& ros_name,
                        const std::string& ros_type, Qos kind) {
  const dds_entity_t topic = Topic(desc, ros_name);
  dds_qos_t* qos = MakeQos(kind, ros_type);
  const dds_entity_t w = dds_create_writer(Participant(), topic, qos, nullptr);
  dds_delete_qos(qos);
  if (w < 0) throw std::runtime_error(Error("DDS writer " + DdsTopicName(ros_name), w));
  return w;
}

dds_entity_t MakeReader(const dds_topic_descriptor_t* desc, const std::string& ros_name,
                        const std::string& ros_type, Qos kind, const dds_listener_t* listener) {
  const dds_entity_t topic = Topic(desc, ros_name);
  dds_qos_t* qos = MakeQos(kind, ros_type);
  const dds_data_representation_id_t both[2] = {DDS_DATA_REPRESENTATION_XCDR1,
                                                DDS_DATA_REPRESENTATION_XCDR2};
  dds_qset_data_representation(qos, 2, both);
  const dds_entity_t r = dds_create_reader(Participant(), topic, qos, listener);
  dds_delete_qos(qos);
  if (r < 0) throw std::runtime_error(Error("DDS reader " + DdsTopicName(ros_name), r));
  return r;
}

int MatchedReaders(dds_entity_t writer) {
  dds_publication_matched_status_t s{};
  if (writer <= 0 || dds_get_publication_matched_status(writer, &s) != DDS_RETCODE_OK) return 0;
  return static_cast<int>(s.current_count);
}

int MatchedWriters(dds_entity_t reader) {
  dds_subscription_matched_status_t s{};
  if (reader <= 0 || dds_get_subscription_matched_status(reader, &s) != DDS_RETCODE_OK) return 0;
  return static_cast<int>(s.current_count);
}

void Delete(dds_entity_t entity) {
  if (entity > 0) dds_delete(entity);
}

}  // namespace mapless::ros2

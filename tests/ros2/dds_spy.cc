// A plain Cyclone DDS program (no mapless code; issue 18's discovery test): joins the ROS domain
// (ROS_DOMAIN_ID; loopback when ROS_LOCALHOST_ONLY=1, as mapless does) and lists, for SECONDS,
// every remote reader and writer it discovers, one JSON object a line:
//   {"kind":"writer","topic":"rt/cmd_vel","type":"geometry_msgs::msg::dds_::Twist_",
//    "reliability":"reliable","history":10,"durability":"volatile","user_data":"typehash=...;"}
//   dds_spy SECONDS
#include <dds/dds.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <thread>

namespace {

std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out;
}

void Drain(dds_entity_t reader, const char* kind, std::set<std::string>* seen) {
  void* samples[16] = {nullptr};
  dds_sample_info_t infos[16];
  const dds_return_t n = dds_take(reader, samples, infos, 16, 16);
  for (dds_return_t i = 0; i < n; ++i) {
    if (!infos[i].valid_data) continue;
    const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
    const std::string topic = e->topic_name ? e->topic_name : "";
    if (topic.rfind("rt/", 0) != 0) continue;  // ROS topics only
    dds_reliability_kind_t rel = DDS_RELIABILITY_BEST_EFFORT;
    dds_duration_t block = 0;
    dds_history_kind_t hist = DDS_HISTORY_KEEP_LAST;
    int32_t depth = 1;
    dds_durability_kind_t dur = DDS_DURABILITY_VOLATILE;
    void* ud = nullptr;
    size_t ud_size = 0;
    dds_qget_reliability(e->qos, &rel, &block);
    dds_qget_history(e->qos, &hist, &depth);
    dds_qget_durability(e->qos, &dur);
    std::string user_data;
    if (dds_qget_userdata(e->qos, &ud, &ud_size) && ud != nullptr) {
      user_data.assign(static_cast<const char*>(ud), ud_size);
      dds_free(ud);
    }
    char line[1024];
    std::snprintf(line, sizeof line,
                  "{\"kind\":\"%s\",\"topic\":\"%s\",\"type\":\"%s\",\"reliability\":\"%s\","
                  "\"history\":%d,\"durability\":\"%s\",\"user_data\":\"%s\"}",
                  kind, Escape(topic).c_str(), Escape(e->type_name ? e->type_name : "").c_str(),
                  rel == DDS_RELIABILITY_RELIABLE ? "reliable" : "best_effort",
                  hist == DDS_HISTORY_KEEP_ALL ? -1 : depth,
                  dur == DDS_DURABILITY_VOLATILE ? "volatile" : "other", Escape(user_data).c_str());
    if (seen->insert(line).second) std::printf("%s\n", line);
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 5.0;
  const char* env = std::getenv("ROS_DOMAIN_ID");
  const dds_domainid_t domain = env ? static_cast<dds_domainid_t>(std::atoi(env)) : 0;
  const char* local = std::getenv("ROS_LOCALHOST_ONLY");
  if (local != nullptr && std::string(local) == "1") {
    dds_create_domain(domain,
                      "<CycloneDDS><Domain><General><Interfaces><NetworkInterface "
                      "address=\"127.0.0.1\"/></Interfaces><AllowMulticast>false</AllowMulticast>"
                      "</General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
                      "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex><Peers><Peer "
                      "address=\"127.0.0.1\"/></Peers></Discovery></Domain></CycloneDDS>");
  }
  const dds_entity_t participant = dds_create_participant(domain, nullptr, nullptr);
  if (participant < 0) {
    std::fprintf(stderr, "dds_spy: no participant: %s\n", dds_strretcode(participant));
    return 1;
  }
  const dds_entity_t pubs =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
  const dds_entity_t subs =
      dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr);
  std::set<std::string> seen;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    Drain(pubs, "writer", &seen);
    Drain(subs, "reader", &seen);
    std::fflush(stdout);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  dds_delete(participant);
  return 0;
}

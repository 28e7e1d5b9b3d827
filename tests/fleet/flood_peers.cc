// The leader under followers that never read (issue 40). Two roles, one program:
//
//   flood_peers leader PEERS SECONDS MAX_RSS_MB
//     makes a funnel route of 300 keyframes of incompressible 320x240 thumbnails (about 25 MB:
//     long enough that every silent peer could pin megabytes), serves it with the leader's server
//     as `mapless lead` configures it (fleet::LeaderServer, default ServerOptions) on loopback,
//     runs `flood_peers peers ...` as a child process and samples its own resident memory (VmRSS)
//     every 20 ms meanwhile. Prints the child's JSON line with the leader's figures added; exit 0
//     when the reader got the whole route and the peak stayed under MAX_RSS_MB.
//   flood_peers peers ENDPOINT PEERS SECONDS
//     PEERS ZeroMQ DEALER sockets ask for the route from record 0 and never read (receive
//     high-water mark 1, a 4 KB receive buffer); then one reading follower asks too and must get
//     every record, 0 to the end, without a gap (records sent again are dropped, as a follower
//     drops them), within SECONDS; then it waits 12 s more (the silent
//     peers are dropped meanwhile) and prints one JSON line.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include "mapless/core/rng.h"
#include "mapless/fleet/record.h"
#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"

namespace {

using Clock = std::chrono::steady_clock;
using namespace mapless::fleet;  // NOLINT: a test program

long RssKb() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "VmRSS:") {
      long kb = 0;
      in >> kb;
      return kb;
    }
    std::getline(in, key);
  }
  return -1;
}

std::vector<Record> BigFunnelRoute(int keyframes) {
  RouteHeader h;
  h.kind = RouteKind::kFunnel;
  h.image_width = 320;
  h.image_height = 240;
  std::vector<Record> records = {HeaderRecord(h)};
  mapless::Rng rng(40);
  for (int i = 0; i < keyframes; ++i) {
    mapless::route::Keyframe kf;
    kf.index = i;
    kf.t_ns = 100'000'000LL * (i + 1);
    kf.thumbnail = cv::Mat(240, 320, CV_8UC1);
    for (auto it = kf.thumbnail.begin<std::uint8_t>(); it != kf.thumbnail.end<std::uint8_t>(); ++it)
      *it = static_cast<std::uint8_t>(rng.UniformInt(256));
    for (int k = 0; k < 40; ++k)
      kf.keypoints.emplace_back(static_cast<float>(rng.Uniform(0, 320)),
                                static_cast<float>(rng.Uniform(0, 240)), 31.0f);
    kf.descriptors = cv::Mat(40, 32, CV_8UC1);
    for (auto it = kf.descriptors.begin<std::uint8_t>(); it != kf.descriptors.end<std::uint8_t>();
         ++it)
      *it = static_cast<std::uint8_t>(rng.UniformInt(256));
    records.push_back(KeyframeRecord(kf));
  }
  records.push_back(EndRecord());
  for (std::size_t i = 0; i < records.size(); ++i) records[i].sequence = i;
  return records;
}

int Leader(const char* self, int peers, double seconds, long max_rss_mb) {
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("mapless_flood_" + std::to_string(getpid())))
          .string();
  std::filesystem::remove_all(dir);
  int rc = 1;
  {
    RouteCopy route(dir);
    route.Apply(BigFunnelRoute(300));
    ServerOptions options;
    options.bind = "tcp://127.0.0.1:*";
    int lines = 0;
    LeaderServer server(route, options, [&](const std::string& line) {
      ++lines;
      std::fprintf(stderr, "[leader] %s\n", line.c_str());
    });
    const long before_kb = RssKb();
    int pipe_fd[2];
    if (pipe(pipe_fd) != 0) return 1;
    const std::string endpoint = server.endpoint();
    const std::string peers_text = std::to_string(peers), seconds_text = std::to_string(seconds);
    const pid_t child = fork();
    if (child == 0) {
      dup2(pipe_fd[1], STDOUT_FILENO);
      close(pipe_fd[0]);
      execl("/proc/self/exe", self, "peers", endpoint.c_str(), peers_text.c_str(),
            seconds_text.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(pipe_fd[1]);
    long peak_kb = before_kb;
    int status = 0;
    while (waitpid(child, &status, WNOHANG) == 0) {
      peak_kb = std::max(peak_kb, RssKb());
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::string json(4096, '\0');
    const ssize_t n = read(pipe_fd[0], json.data(), json.size() - 1);
    close(pipe_fd[0]);
    json.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    while (!json.empty() && (json.back() == '\n' || json.back() == '}')) json.pop_back();
    const ServerStats stats = server.stats();
    std::printf(
        "%s, \"leader_rss_before_mb\": %.1f, \"leader_peak_rss_mb\": %.1f, \"max_rss_mb\": %ld, "
        "\"dropped\": %llu, \"queued_bytes_at_end\": %zu, \"leader_lines\": %d}\n",
        json.empty() ? "{\"error\": \"no result from the peers\"" : json.c_str(),
        before_kb / 1024.0, peak_kb / 1024.0, max_rss_mb,
        static_cast<unsigned long long>(stats.dropped), stats.queued_bytes, lines);
    const bool child_ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    rc = child_ok && peak_kb <= max_rss_mb * 1024 && stats.dropped > 0 ? 0 : 1;
  }
  std::filesystem::remove_all(dir);
  return rc;
}

int Peers(const std::string& endpoint, int peers, double seconds) {
  zmq::context_t context(1);
  context.set(zmq::ctxopt::max_sockets, peers + 16);
  std::vector<std::unique_ptr<zmq::socket_t>> silent;
  const std::string subscribe = EncodeSubscribe(0);
  for (int i = 0; i < peers; ++i) {
    auto s = std::make_unique<zmq::socket_t>(context, zmq::socket_type::dealer);
    s->set(zmq::sockopt::rcvhwm, 1);
    s->set(zmq::sockopt::rcvbuf, 4096);
    s->set(zmq::sockopt::linger, 0);
    s->set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(kMaxMessageBytes));
    s->connect(endpoint);
    s->send(zmq::buffer(subscribe), zmq::send_flags::dontwait);
    silent.push_back(std::move(s));
  }
  std::this_thread::sleep_for(std::chrono::seconds(2));  // their queues fill
  zmq::socket_t reader(context, zmq::socket_type::dealer);
  reader.set(zmq::sockopt::linger, 0);
  reader.set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(kMaxMessageBytes));
  reader.connect(endpoint);
  const auto start = Clock::now();
  reader.send(zmq::buffer(subscribe), zmq::send_flags::none);
  std::uint64_t next = 0;
  bool complete = false, in_order = true;
  const auto deadline = start + std::chrono::duration<double>(seconds);
  auto last_ask = start;
  while (!complete && Clock::now() < deadline) {
    zmq::pollitem_t item{reader.handle(), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, std::chrono::milliseconds(20));
    if (Clock::now() - last_ask > std::chrono::seconds(1)) {  // a follower's "from n" heartbeat
      reader.send(zmq::buffer(EncodeSubscribe(next)), zmq::send_flags::dontwait);
      last_ask = Clock::now();
    }
    zmq::message_t msg;
    while (reader.recv(msg, zmq::recv_flags::dontwait)) {
      const Record r = DecodeRecord(msg.to_string_view());
      if (r.type == RecordType::kHeartbeat) {
        if (r.sequence == next && !r.parts.empty() && r.parts[0] == "1") complete = true;
        continue;
      }
      // Sent again after the reader's "from n" (as a follower asks every second): dropped, as a
      // follower drops a record older than the one it needs. A record past it is a gap.
      if (r.sequence < next) continue;
      if (r.sequence > next) in_order = false;
      next = r.sequence + 1;
    }
  }
  const double took = std::chrono::duration<double>(Clock::now() - start).count();
  std::this_thread::sleep_for(std::chrono::seconds(12));  // the silent peers are dropped
  std::printf(
      "{\"peers\": %d, \"reader_records\": %llu, \"reader_complete\": %s, \"in_order\": %s, "
      "\"reader_s\": %.2f}\n",
      peers, static_cast<unsigned long long>(next), complete ? "true" : "false",
      in_order ? "true" : "false", took);
  std::fflush(stdout);
  return complete && in_order ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "leader" && argc == 5)
    return Leader(argv[0], std::atoi(argv[2]), std::atof(argv[3]), std::atol(argv[4]));
  if (mode == "peers" && argc == 5) return Peers(argv[2], std::atoi(argv[3]), std::atof(argv[4]));
  std::fprintf(stderr,
               "usage: flood_peers leader PEERS SECONDS MAX_RSS_MB\n"
               "       flood_peers peers ENDPOINT PEERS SECONDS\n");
  return 2;
}

// `mapless bench --live-view` (issue 43): what the live view costs the robot's loop and how late
// its clients see a frame, on loopback. The loop is the repeat's (robot::RepeatMethod, the default
// options with the obstacle watch) on the table1_almost_straight teach drive's frames, each
// decision offered to a LiveView. Its per-frame time with no client and with three (two that read,
// one that connects, subscribes to everything and never reads) is measured in alternating passes,
// so that both see the same host speed (target: at most 5% apart). Then, at 30 frames a second,
// the latency from the loop's hand-over to a reading client's receipt of the frame's decision
// (sent after the frame's two JPEG images; target p99 <= 20 ms at 320x240).
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>
// (websocketpp first: it sets up standalone asio)

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "mapless/bench/bench.h"
#include "mapless/bench/timing.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/live/live_view.h"
#include "mapless/robot/link_bench.h"
#include "mapless/robot/methods.h"

namespace mapless::bench {
namespace {

using WsClient = websocketpp::client<websocketpp::config::asio_client>;
using Clock = std::chrono::steady_clock;

// A client that subscribes to every channel and notes when each frame's decision arrives (by
// the frame's time, in milliseconds).
class ReadingClient {
 public:
  ReadingClient(int port, std::function<void(long long t_ms)> on_decision)
      : on_decision_(std::move(on_decision)) {
    ws_.clear_access_channels(websocketpp::log::alevel::all);
    ws_.clear_error_channels(websocketpp::log::elevel::all);
    ws_.init_asio();
    ws_.set_message_handler([this](websocketpp::connection_hdl h, WsClient::message_ptr m) {
      const std::string& p = m->get_payload();
      if (m->get_opcode() == websocketpp::frame::opcode::text) {
        const auto j = nlohmann::json::parse(p, nullptr, false);
        if (j.is_discarded() || j.value("op", "") != "advertise") return;
        nlohmann::json sub = {{"op", "subscribe"}, {"subscriptions", nlohmann::json::array()}};
        for (const auto& c : j["channels"]) {
          sub["subscriptions"].push_back({{"id", c["id"]}, {"channelId", c["id"]}});
          if (c["topic"] == "/mapless/decision") decision_channel_ = c["id"].get<std::uint32_t>();
        }
        std::error_code ec;
        ws_.send(h, sub.dump(), websocketpp::frame::opcode::text, ec);
        subscribed_ = true;
        return;
      }
      if (p.size() < 13 || p[0] != 1) return;
      std::uint32_t sub = 0;
      std::memcpy(&sub, p.data() + 1, 4);
      if (sub != decision_channel_) return;
      const auto j = nlohmann::json::parse(p.substr(13), nullptr, false);
      if (!j.is_discarded() && j.contains("t_s"))
        on_decision_(std::llround(j["t_s"].get<double>() * 1000.0));
    });
    std::error_code ec;
    auto con = ws_.get_connection("ws://127.0.0.1:" + std::to_string(port) + "/", ec);
    con->add_subprotocol(live::kSubprotocolV1, ec);
    ws_.connect(con);
    thread_ = std::thread([this] { ws_.run(); });
  }
  ~ReadingClient() {
    ws_.stop();
    thread_.join();
  }
  bool subscribed() const { return subscribed_; }

 private:
  std::function<void(long long)> on_decision_;
  WsClient ws_;
  std::thread thread_;
  std::atomic<bool> subscribed_{false};
  std::atomic<std::uint32_t> decision_channel_{0};
};

// A client that connects, subscribes to every channel (ids 1-9) and never reads again.
struct StalledClient {
  asio::io_context io;
  asio::ip::tcp::socket socket{io};
  explicit StalledClient(int port) {
    socket.connect({asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)});
    socket.set_option(asio::socket_base::receive_buffer_size(4096));
    const std::string upgrade =
        "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
        "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n";
    asio::write(socket, asio::buffer(upgrade));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    for (int id = 1; id <= 9; ++id) {
      const std::string text = R"({"op":"subscribe","subscriptions":[{"id":)" + std::to_string(id) +
                               R"(,"channelId":)" + std::to_string(id) + "}]}";
      std::string frame = {'\x81', static_cast<char>(0x80 | text.size()), 0, 0, 0, 0};
      frame += text;  // a zero mask leaves the payload as it is
      asio::write(socket, asio::buffer(frame));
    }
  }
};

struct Drive {
  std::vector<robot::Observation> frames;
  std::vector<Pose2> truth;
  std::shared_ptr<const route::Route> route;
};

Drive TeachDrive() {
  const sim::Scenario scenario = BenchScenario("table1_almost_straight");
  Drive d;
  sim::DriveTaughtPath(scenario, {}, [&](const sim::DriveFrame& f) {
    robot::Observation o;
    if (f.image.channels() == 3) {
      cv::cvtColor(f.image, o.image, cv::COLOR_BGR2GRAY);
    } else {
      o.image = f.image.clone();
    }
    o.t_ns = f.t_ns;
    o.odometry = f.odometry;
    d.frames.push_back(o);
    d.truth.push_back(f.truth);
  });
  d.route = eval::TeachOnSimulator(scenario, navigation::TeachOptions{}).route;
  return d;
}

// The loop over the drive (a fresh method each pass): per-frame times of Step + Frame, ms.
void LoopPass(const Drive& d, live::LiveView& view, std::vector<double>* ms,
              double frame_period_s = 0.0,
              const std::function<void(int, Clock::time_point)>& offered = {}) {
  robot::RepeatMethod method(d.route, navigation::RepeatOptions{});
  const Clock::time_point start = Clock::now();
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    if (frame_period_s > 0)
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(frame_period_s * i)));
    const auto t0 = Clock::now();
    const robot::Decision decision = method.Step(d.frames[i]);
    if (offered) offered(static_cast<int>(i), Clock::now());
    view.Frame(d.frames[i], decision, decision.command, d.truth[i]);
    ms->push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    if (decision.done()) break;
  }
}

// Hostile clients (issue 67), each on a thread of its own, until stopped: never reading and
// subscribed to everything; subscribing and unsubscribing again and again without reading (each
// subscribe sends the route again); flooding bad messages (cut off, then again); connecting and
// going away in a loop; and 200 connections at once that never finish their handshake.
class HostileClients {
 public:
  explicit HostileClients(int port) : port_(port) {
    for (int i = 0; i < 3; ++i) stalled_.push_back(std::make_unique<StalledClient>(port));
    threads_.emplace_back([this] { Resubscribe(); });
    threads_.emplace_back([this] { Resubscribe(); });
    threads_.emplace_back([this] { Flood(); });
    threads_.emplace_back([this] { Reconnect(); });
    threads_.emplace_back([this] { HalfOpen(); });
  }
  ~HostileClients() {
    stop_ = true;
    for (std::thread& t : threads_) t.join();
  }

 private:
  static std::string Masked(const std::string& text) {
    std::string frame = {'\x81'};
    if (text.size() < 126) {
      frame += static_cast<char>(0x80 | text.size());
    } else {
      frame += static_cast<char>(0x80 | 126);
      frame += static_cast<char>(text.size() >> 8);
      frame += static_cast<char>(text.size() & 0xff);
    }
    frame += std::string(4, '\0');  // a zero mask leaves the payload as it is
    return frame + text;
  }
  // A handshake on a fresh socket (nothing read back); false when refused or closed.
  bool Open(asio::ip::tcp::socket& socket) {
    std::error_code ec;
    socket.connect({asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port_)}, ec);
    if (ec) return false;
    socket.set_option(asio::socket_base::receive_buffer_size(4096), ec);
    const std::string upgrade =
        "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
        "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n";
    asio::write(socket, asio::buffer(upgrade), ec);
    return !ec;
  }
  void Sleep(int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); }
  void Resubscribe() {
    asio::io_context io;
    asio::ip::tcp::socket socket(io);
    if (!Open(socket)) return;
    Sleep(200);
    while (!stop_) {  // 10 messages every 150 ms: under the flood limit of 100 a second
      std::error_code ec;
      for (int id = 1; id <= 9 && !ec; ++id)
        asio::write(socket,
                    asio::buffer(Masked(R"({"op":"subscribe","subscriptions":[{"id":)" +
                                        std::to_string(id) + R"(,"channelId":)" +
                                        std::to_string(id) + "}]}")),
                    ec);
      asio::write(
          socket,
          asio::buffer(Masked(R"({"op":"unsubscribe","subscriptionIds":[1,2,3,4,5,6,7,8,9]})")),
          ec);
      if (ec) return;  // cut off
      Sleep(150);
    }
  }
  void Flood() {
    while (!stop_) {
      asio::io_context io;
      asio::ip::tcp::socket socket(io);
      if (Open(socket)) {
        Sleep(100);
        std::error_code ec;
        for (int i = 0; i < 400 && !ec && !stop_; ++i)
          asio::write(
              socket,
              asio::buffer(Masked("{\"op\": \"advertise\", \"junk\": " + std::to_string(i) + "}")),
              ec);
      }
      Sleep(500);
    }
  }
  void Reconnect() {
    while (!stop_) {
      asio::io_context io;
      asio::ip::tcp::socket socket(io);
      Open(socket);
      Sleep(50);
    }
  }
  void HalfOpen() {
    asio::io_context io;
    std::vector<std::unique_ptr<asio::ip::tcp::socket>> sockets;
    for (int i = 0; i < 200 && !stop_; ++i) {
      auto s = std::make_unique<asio::ip::tcp::socket>(io);
      std::error_code ec;
      s->connect({asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port_)}, ec);
      if (!ec) asio::write(*s, asio::buffer(std::string("GET / HTTP/1.1\r\nHost: x\r\n")), ec);
      sockets.push_back(std::move(s));
    }
    while (!stop_) Sleep(20);
  }

  int port_;
  std::atomic<bool> stop_{false};
  std::vector<std::unique_ptr<StalledClient>> stalled_;
  std::vector<std::thread> threads_;
};

double PeakRssMb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return -1.0;
}

// The loop with no client and under the hostile clients, in alternating passes; the lines the
// server logged meanwhile; the process's peak memory.
void BenchHostile(const Drive& drive, nlohmann::json* j) {
  live::LiveViewOptions options;
  options.address = live::ParseAddress("127.0.0.1:0");
  options.route = live::RoutePoses(*drive.route);
  std::atomic<int> lines{0};
  options.server.log = [&lines](const std::string&) { ++lines; };
  live::LiveView view("repeat", options);
  std::vector<double> none_ms, hostile_ms;
  double hostile_s = 0.0;
  for (int round = 0; round < 3; ++round) {
    LoopPass(drive, view, &none_ms);
    HostileClients hostile(view.port());
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const auto start = Clock::now();
    LoopPass(drive, view, &hostile_ms);
    hostile_s += std::chrono::duration<double>(Clock::now() - start).count();
  }
  const live::ServerStats stats = view.server().stats();
  (*j)["live_hostile_loop_0_clients_ms"] = Median(none_ms);
  (*j)["live_hostile_loop_ms"] = Median(hostile_ms);
  (*j)["live_hostile_over_0_clients"] = Median(hostile_ms) / Median(none_ms);
  (*j)["live_hostile_log_lines"] = lines.load();
  (*j)["live_hostile_seconds"] = hostile_s;
  (*j)["live_hostile_clients_cut_off"] = stats.clients_cut_off;
  (*j)["live_hostile_connections_refused"] = stats.connections_refused;
  (*j)["live_hostile_messages_dropped"] = stats.messages_dropped + stats.images_dropped;
  (*j)["live_hostile_log_lines_suppressed"] = stats.log_lines_suppressed;
  (*j)["live_peak_rss_mb"] = PeakRssMb();
}

// --live-rate: frames 0.1 s apart in the run's time, offered as fast as they come, with a client
// watching (and the hostile ones): the wall-clock time they take, against the time / rate.
void BenchPace(const Drive& drive, double rate, nlohmann::json* j) {
  live::LiveViewOptions options;
  options.address = live::ParseAddress("127.0.0.1:0");
  options.pace_rate = rate;
  live::LiveView view("repeat", options);
  ReadingClient watcher(view.port(), [](long long) {});
  while (!watcher.subscribed()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  HostileClients hostile(view.port());
  robot::Decision d;
  d.state = robot::MethodState::kDriving;
  const int n = 60;
  const auto start = Clock::now();
  for (int i = 0; i < n; ++i) {
    robot::Observation o = drive.frames[static_cast<std::size_t>(i) % drive.frames.size()];
    o.t_ns = static_cast<Timestamp>(i) * 100'000'000;
    view.Frame(o, d, Twist2{}, std::nullopt);
  }
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  // The first frame starts the clock: n - 1 periods of 0.1 s of the run's time.
  (*j)["live_pace_rate"] = rate;
  (*j)["live_pace_run_s_per_wall_s"] = (n - 1) * 0.1 / wall_s;
}

}  // namespace

void BenchLive(nlohmann::json* j) {
  cv::setNumThreads(1);
  const Drive drive = TeachDrive();
  live::LiveViewOptions options;
  options.address = live::ParseAddress("127.0.0.1:0");
  options.route = live::RoutePoses(*drive.route);
  live::LiveView view("repeat", options);
  std::mutex mu;
  std::map<long long, Clock::time_point> offered_at;  // by the frame's time, ms
  std::vector<double> latency_ms;
  const auto on_decision = [&](long long t_ms) {
    const auto now = Clock::now();
    std::lock_guard<std::mutex> lock(mu);
    const auto it = offered_at.find(t_ms);
    if (it != offered_at.end())
      latency_ms.push_back(std::chrono::duration<double, std::milli>(now - it->second).count());
  };
  std::vector<double> none_ms, three_ms;
  for (int round = 0; round < 3; ++round) {
    LoopPass(drive, view, &none_ms);
    ReadingClient a(view.port(), [](long long) {});
    ReadingClient b(view.port(), [](long long) {});
    StalledClient stalled(view.port());
    while (!a.subscribed() || !b.subscribed() || view.server().clients() < 3)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    LoopPass(drive, view, &three_ms);
  }
  (*j)["live_loop_0_clients_ms"] = Median(none_ms);
  (*j)["live_loop_3_clients_ms"] = Median(three_ms);
  (*j)["live_loop_3_over_0_clients"] = Median(three_ms) / Median(none_ms);
  {
    ReadingClient a(view.port(), on_decision);
    ReadingClient b(view.port(), [](long long) {});
    StalledClient stalled(view.port());
    while (!a.subscribed() || !b.subscribed())
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::vector<double> ms;
    LoopPass(drive, view, &ms, 1.0 / 30.0, [&](int i, Clock::time_point t) {
      std::lock_guard<std::mutex> lock(mu);
      offered_at[std::llround(ToSeconds(drive.frames[static_cast<std::size_t>(i)].t_ns) * 1000.0)] =
          t;
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  std::lock_guard<std::mutex> lock(mu);
  (*j)["live_latency_samples"] = latency_ms.size();
  (*j)["live_latency_median_ms"] = latency_ms.empty() ? -1.0 : robot::Percentile(latency_ms, 0.5);
  (*j)["live_latency_p99_ms"] = latency_ms.empty() ? -1.0 : robot::Percentile(latency_ms, 0.99);
  const live::ServerStats stats = view.server().stats();
  (*j)["live_images_dropped"] = stats.images_dropped;
  (*j)["live_clients_cut_off"] = stats.clients_cut_off;
  BenchHostile(drive, j);
  BenchPace(drive, 2.0, j);
}

}  // namespace mapless::bench

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
#include <map>
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
}

}  // namespace mapless::bench

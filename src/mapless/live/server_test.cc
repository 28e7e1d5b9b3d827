// The live view's server on loopback, against websocketpp's client and raw sockets: both
// subprotocols, every channel, bad input, a stalled client, a half-open connection, the page.
#include "mapless/live/server.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <thread>
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

#include "mapless/core/check.h"
#include "mapless/live/live_view.h"
#include "mapless/rosmsg/messages.h"

namespace mapless::live {
namespace {

using WsClient = websocketpp::client<websocketpp::config::asio_client>;
using namespace std::chrono_literals;

// A client on its own thread; what it receives, in order.
class TestClient {
 public:
  TestClient(int port, const std::string& subprotocol) {
    ws_.clear_access_channels(websocketpp::log::alevel::all);
    ws_.clear_error_channels(websocketpp::log::elevel::all);
    ws_.init_asio();
    ws_.set_open_handler([this](websocketpp::connection_hdl) { Set(&open_); });
    ws_.set_fail_handler([this](websocketpp::connection_hdl) { Set(&closed_); });
    ws_.set_close_handler([this](websocketpp::connection_hdl) { Set(&closed_); });
    ws_.set_message_handler([this](websocketpp::connection_hdl, WsClient::message_ptr m) {
      std::lock_guard<std::recursive_mutex> lock(mu_);
      (m->get_opcode() == websocketpp::frame::opcode::text ? texts_ : binaries_)
          .push_back(m->get_payload());
      cv_.notify_all();
    });
    std::error_code ec;
    con_ = ws_.get_connection("ws://127.0.0.1:" + std::to_string(port) + "/", ec);
    if (!subprotocol.empty()) con_->add_subprotocol(subprotocol, ec);
    ws_.connect(con_);
    thread_ = std::thread([this] { ws_.run(); });
  }
  ~TestClient() {
    std::error_code ec;
    if (Opened() && !Closed()) ws_.close(con_, websocketpp::close::status::normal, "", ec);
    Wait([this] { return closed_; }, 2s);
    ws_.stop();
    thread_.join();
  }
  bool Wait(const std::function<bool()>& done, std::chrono::milliseconds timeout = 5000ms) {
    std::unique_lock<std::recursive_mutex> lock(mu_);
    return cv_.wait_for(lock, timeout, done);
  }
  bool Opened() {
    return Wait([this] { return open_ || closed_; }) && open_;
  }
  bool Closed() {
    std::lock_guard<std::recursive_mutex> lock(mu_);
    return closed_;
  }
  void Send(const std::string& text,
            websocketpp::frame::opcode::value op = websocketpp::frame::opcode::text) {
    std::error_code ec;
    ws_.send(con_, text, op, ec);
  }
  std::string subprotocol() { return con_->get_response_header("Sec-WebSocket-Protocol"); }
  std::vector<std::string> texts() {
    std::lock_guard<std::recursive_mutex> lock(mu_);
    return texts_;
  }
  std::vector<std::string> binaries() {
    std::lock_guard<std::recursive_mutex> lock(mu_);
    return binaries_;
  }
  // The text messages with op `op`.
  std::vector<nlohmann::json> Ops(const std::string& op) {
    std::vector<nlohmann::json> out;
    for (const std::string& t : texts()) {
      auto j = nlohmann::json::parse(t);
      if (j["op"] == op) out.push_back(j);
    }
    return out;
  }
  // Subscribes to the channels advertised (all, or those in `only`), subscription id = channel
  // id + 100.
  void SubscribeAll(const std::vector<std::uint32_t>& only = {}) {
    ASSERT_TRUE(Wait([this] { return texts_.size() >= 2; }));
    nlohmann::json sub = {{"op", "subscribe"}, {"subscriptions", nlohmann::json::array()}};
    const std::vector<nlohmann::json> advertised = Ops("advertise");
    for (const auto& c : advertised.at(0)["channels"]) {
      const auto id = c["id"].get<std::uint32_t>();
      if (only.empty() || std::find(only.begin(), only.end(), id) != only.end())
        sub["subscriptions"].push_back({{"id", id + 100}, {"channelId", id}});
    }
    Send(sub.dump());
  }

 private:
  void Set(bool* flag) {
    std::lock_guard<std::recursive_mutex> lock(mu_);
    *flag = true;
    cv_.notify_all();
  }
  WsClient ws_;
  WsClient::connection_ptr con_;
  std::thread thread_;
  std::recursive_mutex mu_;  // Wait's predicates read under it
  std::condition_variable_any cv_;
  bool open_ = false, closed_ = false;
  std::vector<std::string> texts_, binaries_;
};

FrameView AFrame(int i, int width = 320, int height = 240) {
  FrameView f;
  f.method = "repeat";
  f.frame = i;
  f.observation.image = cv::Mat(height, width, CV_8UC1);
  cv::randu(f.observation.image, 0, 255);
  f.observation.t_ns = 2'000'000'000LL + i;
  f.observation.odometry = Pose2{0.1 * i, 0.0, 0.0};
  f.decision.state = robot::MethodState::kDriving;
  f.decision.status = "driving";
  f.command = {0.2, 0.0};
  return f;
}

std::unique_ptr<Server> AServer(ServerOptions options, std::vector<std::string>* log = nullptr,
                                std::mutex* log_mu = nullptr) {
  options.address = ParseAddress("127.0.0.1:0");
  if (log != nullptr)
    options.log = [log, log_mu](const std::string& line) {
      std::lock_guard<std::mutex> lock(*log_mu);
      log->push_back(line);
    };
  return std::make_unique<Server>(RunChannels("repeat", true),
                                  std::make_unique<Feed>(std::vector<Pose2>{{0, 0, 0}, {2, 0, 0}}),
                                  LivePage(), options);
}

// Offers frames until `done` or 5 s.
bool OfferUntil(Server& server, const std::function<bool()>& done, int width = 320,
                int height = 240) {
  for (int i = 0; i < 500; ++i) {
    if (done()) return true;
    server.Offer(AFrame(i, width, height));
    std::this_thread::sleep_for(10ms);
  }
  return done();
}

TEST(LiveServer, SpeaksBothSubprotocolsEchoesTheOneOfferedAndAdvertisesEveryChannel) {
  ServerOptions defaults;
  auto server = AServer(defaults);
  for (const char* sub : {kSubprotocolSdk, kSubprotocolV1}) {
    SCOPED_TRACE(sub);
    TestClient c(server->port(), sub);
    ASSERT_TRUE(c.Opened());
    EXPECT_EQ(c.subprotocol(), sub);
    ASSERT_TRUE(c.Wait([&] { return c.texts().size() >= 2; }));
    const auto info = nlohmann::json::parse(c.texts()[0]);
    EXPECT_EQ(info["op"], "serverInfo");
    EXPECT_EQ(info["capabilities"], nlohmann::json::array({"time"}));
    EXPECT_EQ(c.Ops("advertise").at(0)["channels"].size(), RunChannels("repeat", true).size());
  }
  TestClient none(server->port(), "");
  EXPECT_FALSE(none.Opened());
  TestClient other(server->port(), "chat");
  EXPECT_FALSE(other.Opened());
}

// A client that may have missed the greeting (it said nothing a second after it) gets it once more;
// one that subscribed does not.
TEST(LiveServer, AClientThatSaysNothingIsGreetedAgainOnceAndASubscriberIsNot) {
  ServerOptions defaults;
  auto server = AServer(defaults);
  TestClient silent(server->port(), kSubprotocolSdk);
  TestClient subscriber(server->port(), kSubprotocolSdk);
  ASSERT_TRUE(silent.Opened());
  ASSERT_TRUE(subscriber.Opened());
  subscriber.SubscribeAll();
  ASSERT_TRUE(silent.Wait([&] { return silent.Ops("advertise").size() >= 2; }, 5000ms));
  std::this_thread::sleep_for(1500ms);  // no third greeting, and none for the subscriber
  EXPECT_EQ(silent.Ops("serverInfo").size(), 2u);
  EXPECT_EQ(silent.Ops("advertise").size(), 2u);
  EXPECT_EQ(subscriber.Ops("serverInfo").size(), 1u);
  EXPECT_EQ(subscriber.Ops("advertise").size(), 1u);
}

TEST(LiveServer, ASubscriberGetsEveryChannelWithTheRunsTimestamps) {
  ServerOptions defaults;
  auto server = AServer(defaults);
  TestClient c(server->port(), kSubprotocolV1);
  ASSERT_TRUE(c.Opened());
  c.SubscribeAll();
  std::set<std::uint32_t> seen;
  auto all = [&] {
    seen.clear();
    for (const std::string& b : c.binaries()) {
      if (b[0] != 1) continue;
      std::uint32_t sub = 0;
      std::memcpy(&sub, b.data() + 1, 4);
      seen.insert(sub - 100);
    }
    return seen.size() == RunChannels("repeat", true).size();
  };
  ASSERT_TRUE(OfferUntil(*server, all))
      << ::testing::PrintToString(seen) << " seen; " << ::testing::PrintToString(c.texts());
  for (const std::string& b : c.binaries()) {
    ASSERT_GE(b.size(), 9u);
    std::uint64_t t = 0;
    std::memcpy(&t, b.data() + (b[0] == 1 ? 5 : 1), 8);
    EXPECT_GE(t, 2'000'000'000u);
    std::uint32_t sub = 0;
    std::memcpy(&sub, b.data() + 1, 4);
    if (b[0] == 1 && sub - 100 == kCameraChannel) {
      const auto img =
          rosmsg::DecodeCompressedImage(std::string_view(b).substr(13), rosmsg::Wire::kCdr);
      EXPECT_EQ(img.format, "jpeg");
      EXPECT_EQ(static_cast<std::uint64_t>(img.header.stamp_ns), t);
    }
  }
  EXPECT_GT(server->stats().messages_sent, 0u);
}

// The simulator's first frame is at time 0: a client that subscribes after it still gets the route
// and the path so far (CI once recorded a run without its route: 0 was taken for "no frame yet").
TEST(LiveServer, AClientThatSubscribesAfterAFrameAtTimeZeroGetsTheRoute) {
  ServerOptions defaults;
  auto server = AServer(defaults);
  FrameView first = AFrame(0);
  first.observation.t_ns = 0;
  server->Offer(first);
  std::this_thread::sleep_for(200ms);  // the frame goes out to nobody
  TestClient c(server->port(), kSubprotocolSdk);
  ASSERT_TRUE(c.Opened());
  c.SubscribeAll();
  auto got_route = [&] {
    for (const std::string& b : c.binaries()) {
      std::uint32_t sub = 0;
      if (b.size() >= 5 && b[0] == 1) std::memcpy(&sub, b.data() + 1, 4);
      if (sub == 100 + kRouteChannel) return true;
    }
    return false;
  };
  EXPECT_TRUE(c.Wait(got_route)) << c.binaries().size() << " messages, none on the route";
}

TEST(LiveServer, BadInputIsAnsweredLoggedOnceAndChangesNothing) {
  std::vector<std::string> log;
  std::mutex log_mu;
  ServerOptions defaults;
  defaults.max_log_lines_per_s = 100;  // every kind's line counted here, none held back
  auto server = AServer(defaults, &log, &log_mu);
  TestClient bad(server->port(), kSubprotocolSdk);
  TestClient good(server->port(), kSubprotocolSdk);
  ASSERT_TRUE(bad.Opened());
  ASSERT_TRUE(good.Opened());
  good.SubscribeAll();
  for (int i = 0; i < 3; ++i) {
    bad.Send("{not json");
    bad.Send(R"({"op":"explode"})");
    bad.Send(R"({"op":"advertise","channels":[]})");
    bad.Send(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":999}]})");
    bad.Send(std::string("\x01\x02\x03", 3), websocketpp::frame::opcode::binary);
  }
  ASSERT_TRUE(bad.Wait([&] { return bad.Ops("status").size() >= 15; }));
  EXPECT_FALSE(bad.Closed());
  {
    std::lock_guard<std::mutex> lock(log_mu);
    int about_bad = 0;
    for (const std::string& l : log)
      about_bad +=
          l.find("ignored") != std::string::npos || l.find("no channel") != std::string::npos;
    EXPECT_EQ(about_bad, 5) << "each kind of bad input once";
  }
  // An oversized frame closes that client (1009), and only it.
  bad.Send(std::string(200 * 1024, 'x'));
  EXPECT_TRUE(bad.Wait([&] { return bad.Closed(); }));
  const std::size_t before = good.binaries().size();
  EXPECT_TRUE(OfferUntil(*server, [&] { return good.binaries().size() > before + 10; }));
  EXPECT_FALSE(good.Closed());
}

TEST(LiveServer, AFloodOfSubscribeMessagesCutsThatClientOff) {
  ServerOptions options;
  options.max_requests_per_s = 50;
  auto server = AServer(options);
  TestClient flood(server->port(), kSubprotocolV1);
  ASSERT_TRUE(flood.Opened());
  for (int i = 0; i < 500; ++i)
    flood.Send(R"({"op":"subscribe","subscriptions":[{"id":)" + std::to_string(i) +
               R"(,"channelId":3}]})");
  EXPECT_TRUE(flood.Wait([&] { return flood.Closed(); }));
  EXPECT_EQ(server->stats().clients_cut_off, 1u);
  TestClient after(server->port(), kSubprotocolV1);
  EXPECT_TRUE(after.Opened());
}

// A raw TCP client: `request` written, then nothing read.
struct RawClient {
  asio::io_context io;
  asio::ip::tcp::socket socket{io};
  // receive_buffer: set before the connection is made, so that the window the kernel offers is
  // small from the first segment (set after, the window already offered would still be taken).
  explicit RawClient(int port, int receive_buffer = 0) {
    const asio::ip::tcp::endpoint server{asio::ip::make_address("127.0.0.1"),
                                         static_cast<unsigned short>(port)};
    socket.open(server.protocol());
    if (receive_buffer > 0)
      socket.set_option(asio::socket_base::receive_buffer_size(receive_buffer));
    socket.connect(server);
  }
  void Write(const std::string& bytes) { asio::write(socket, asio::buffer(bytes)); }
  // Reads until the peer closes or `timeout`; what was read.
  std::string ReadAll(std::chrono::seconds timeout, bool* closed) {
    std::string out;
    socket.non_blocking(true);
    const auto end = std::chrono::steady_clock::now() + timeout;
    char buf[65536];
    *closed = false;
    while (std::chrono::steady_clock::now() < end) {
      std::error_code ec;
      const std::size_t n = socket.read_some(asio::buffer(buf), ec);
      if (ec == asio::error::would_block) {
        std::this_thread::sleep_for(20ms);
        continue;
      }
      if (ec) {
        *closed = true;
        break;
      }
      out.append(buf, n);
    }
    return out;
  }
};

std::string Upgrade(const char* subprotocol) {
  return std::string("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n") +
         "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n" +
         "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: " + subprotocol + "\r\n\r\n";
}

// A client's text frame (clients mask: RFC 6455), for payloads under 126 bytes.
std::string MaskedText(const std::string& payload) {
  std::string f = {'\x81', static_cast<char>(0x80 | payload.size()), 1, 2, 3, 4};
  for (std::size_t i = 0; i < payload.size(); ++i)
    f.push_back(payload[i] ^ "\x01\x02\x03\x04"[i % 4]);
  return f;
}

TEST(LiveServer, AStalledClientLosesImagesThenIsCutOffAndTheOthersGoOn) {
  ServerOptions options;
  options.max_buffered_bytes = 256 * 1024;
  options.stall_timeout_s = 1.0;
  auto server = AServer(options);
  RawClient stalled(server->port());
  stalled.Write(Upgrade(kSubprotocolV1));
  std::this_thread::sleep_for(200ms);
  stalled.Write(MaskedText(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]})"));
  stalled.Write(MaskedText(R"({"op":"subscribe","subscriptions":[{"id":2,"channelId":2}]})"));
  stalled.socket.set_option(asio::socket_base::receive_buffer_size(4096));
  // A client that reads what it subscribed to (the decisions: small, it keeps up under the
  // sanitizers too).
  TestClient reader(server->port(), kSubprotocolV1);
  ASSERT_TRUE(reader.Opened());
  reader.SubscribeAll({kDecisionChannel});
  // Large, incompressible frames, until the stalled client is cut off.
  EXPECT_TRUE(OfferUntil(
      *server, [&] { return server->stats().clients_cut_off >= 1; }, 640, 480));
  EXPECT_EQ(server->stats().clients_cut_off, 1u);
  EXPECT_GT(server->stats().images_dropped, 0u);
  for (int i = 0; i < 200 && server->clients() != 1; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(server->clients(), 1u);  // the stalled one gone, the reader still there
  const std::size_t before = reader.binaries().size();
  EXPECT_TRUE(OfferUntil(*server, [&] { return reader.binaries().size() > before + 10; }));
  EXPECT_FALSE(reader.Closed());
}

TEST(LiveServer, TwoHundredClientsGetAFewLinesWithACountAndConnectionsAreBounded) {
  ServerOptions options;
  options.max_connections = 40;
  options.handshake_timeout_s = 1.0;
  std::vector<std::string> log;
  std::mutex log_mu;
  auto server = AServer(options, &log, &log_mu);
  // 200 connections at once: 20 send a whole handshake and then never read (8 become clients,
  // the others are refused), 180 send half a request and wait (held until the handshake times
  // out: past 40 open connections they are closed as they are accepted).
  std::vector<std::unique_ptr<RawClient>> clients;
  for (int i = 0; i < 200; ++i) {
    clients.push_back(std::make_unique<RawClient>(server->port()));
    std::error_code ignored;
    asio::write(clients.back()->socket,
                asio::buffer(i < 20 ? Upgrade(kSubprotocolV1) : "GET / HTTP/1.1\r\nHost: x\r\n"),
                ignored);
  }
  std::this_thread::sleep_for(1500ms);
  EXPECT_LE(server->clients(), options.max_clients);
  EXPECT_GT(server->stats().connections_refused, 0u);
  EXPECT_GT(server->stats().log_lines_suppressed, 0u);
  std::lock_guard<std::mutex> lock(log_mu);
  // A few lines a second (the test took about 2 s) and the count of the others.
  EXPECT_LE(log.size(), 20u) << log.size() << " lines";
  bool counted = false;
  for (const std::string& line : log)
    counted = counted || line.find("more lines about clients not shown") != std::string::npos;
  EXPECT_TRUE(counted);
}

TEST(LiveServer, AClientThatResubscribesWithoutReadingCannotGrowItsQueue) {
  ServerOptions options;
  options.max_buffered_bytes = 64 * 1024;
  options.stall_timeout_s = 600.0;      // not cut off: what it can queue is what is measured
  options.handshake_timeout_s = 600.0;  // nor closed for its unanswered pings (every 5 s)
  // Nor cut off as a flood: a server slowed down (by sanitizers, emulation) reads its requests in
  // bursts, and the flood limit has its own test.
  options.max_requests_per_s = 100000;
  auto server = AServer(options);
  server->Offer(AFrame(0));  // a frame: the route is latched from now on
  RawClient hostile(server->port(), 4096);
  hostile.Write(Upgrade(kSubprotocolV1));
  // Every channel subscribed for good (ids 101-109): the frames' images fill the kernel's socket
  // buffers (how much they take depends on the machine and its load) and then the queue.
  for (int id = 1; id <= 9; ++id)
    hostile.Write(MaskedText(R"({"op":"subscribe","subscriptions":[{"id":)" +
                             std::to_string(100 + id) + R"(,"channelId":)" + std::to_string(id) +
                             "}]}"));
  // And every channel subscribed and unsubscribed again and again (a few dozen a second):
  // each subscribe sends the latched route again, to a client that reads nothing. Rounds go on
  // until the server drops (or 400 rounds, a minute: a queue that grows without bound never
  // drops, and fails here).
  int rounds = 0;
  for (; rounds < 400 && server->stats().messages_dropped == 0; ++rounds) {
    for (int id = 1; id <= 9; ++id)
      hostile.Write(MaskedText(R"({"op":"subscribe","subscriptions":[{"id":)" + std::to_string(id) +
                               R"(,"channelId":)" + std::to_string(id) + "}]}"));
    hostile.Write(MaskedText(R"({"op":"unsubscribe","subscriptionIds":[1,2,3,4,5,6,7,8,9]})"));
    server->Offer(AFrame(rounds + 1, 640, 480));
    std::this_thread::sleep_for(150ms);
  }
  // Its queue went over the bound: what came then (the route again, the time) was dropped.
  EXPECT_GT(server->stats().messages_dropped, 0u) << rounds << " rounds";
  EXPECT_EQ(server->clients(), 1u);
}

TEST(LiveServer, AHalfOpenConnectionIsClosed) {
  ServerOptions options;
  options.handshake_timeout_s = 0.5;
  auto server = AServer(options);
  RawClient silent(server->port());
  silent.Write("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n");  // and never the end of the request
  bool closed = false;
  silent.ReadAll(5s, &closed);
  EXPECT_TRUE(closed);
}

TEST(LiveServer, ServesThePageAndNothingElse) {
  ServerOptions defaults;
  auto server = AServer(defaults);
  {
    RawClient http(server->port());
    http.Write("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
    bool closed = false;
    const std::string response = http.ReadAll(5s, &closed);
    EXPECT_NE(response.find("HTTP/1.1 200"), std::string::npos);
    EXPECT_NE(response.find("<title>mapless live</title>"), std::string::npos);
    EXPECT_NE(response.find("Content-Security-Policy: default-src 'none'"), std::string::npos);
    // Self-contained: no address of anywhere else.
    EXPECT_EQ(LivePage().find("http://"), std::string::npos);
    EXPECT_EQ(LivePage().find("https://"), std::string::npos);
  }
  RawClient http(server->port());
  http.Write("GET /etc/passwd HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  bool closed = false;
  EXPECT_NE(http.ReadAll(5s, &closed).find("HTTP/1.1 404"), std::string::npos);
}

TEST(LiveServer, RefusesAnAddressInUseWithAClearError) {
  ServerOptions defaults;
  auto first = AServer(defaults);
  ServerOptions options;
  options.address.port = first->port();
  try {
    Server second(RunChannels("repeat", false), std::make_unique<Feed>(std::vector<Pose2>{}), "",
                  options);
    FAIL() << "bound a port in use";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(first->port())), std::string::npos);
  }
}

}  // namespace
}  // namespace mapless::live

#include "mapless/live/server.h"

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>
// (websocketpp before the rest: it defines what asio needs standalone)

#include <algorithm>
#include <chrono>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "mapless/core/check.h"

namespace mapless::live {
namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using Hdl = websocketpp::connection_hdl;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Client {
  std::string name;  // "127.0.0.1:50412 (foxglove.sdk.v1)"
  Subscriptions subscriptions;
  std::optional<Clock::time_point> full_since;  // its queue over the limit since
  Clock::time_point window_start = Clock::now();
  int requests_in_window = 0;
  std::set<std::string> told;  // the kinds of bad input already logged for it (at most 32)
  bool cut_off = false;        // its socket is closed; what it sent before is ignored
  bool heard = false;          // it has sent a message
};

}  // namespace

Address ParseAddress(const std::string& text) {
  Address a;
  std::string port = text;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find("]:");
    MAPLESS_CHECK(close != std::string::npos, "--live " << text << ": expected [ADDRESS]:PORT");
    a.host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else if (const auto colon = text.rfind(':'); colon != std::string::npos) {
    a.host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  if (a.host == "localhost") a.host = "127.0.0.1";
  MAPLESS_CHECK(!a.host.empty(), "--live " << text << ": an empty address");
  std::error_code ec;
  (void)asio::ip::make_address(a.host, ec);
  MAPLESS_CHECK(!ec, "--live " << text << ": " << a.host << " is not an IP address");
  MAPLESS_CHECK(!port.empty() && port.size() <= 5 &&
                    port.find_first_not_of("0123456789") == std::string::npos,
                "--live " << text << ": the port must be a number from 0 to 65535");
  a.port = std::stoi(port);
  MAPLESS_CHECK(a.port <= 65535, "--live " << text << ": the port must be from 0 to 65535");
  return a;
}

struct Server::Impl {
  ServerOptions options;
  std::vector<Channel> channels;
  std::vector<std::uint32_t> channel_ids;
  std::unique_ptr<Feed> feed;  // the server's thread only
  std::string page;
  WsServer ws;
  std::map<Hdl, Client, std::owner_less<Hdl>> clients;  // the server's thread only
  std::vector<Hdl> connections;  // every connection accepted and not yet gone (server's thread)
  std::vector<Hdl> validated;    // handshakes accepted, not yet open (server's thread)
  // Lines about clients in the current second, and those not shown since the last summary.
  Clock::time_point log_window = Clock::now();
  int log_lines_in_window = 0;
  std::uint64_t log_suppressed = 0;
  std::atomic<std::size_t> client_count{0};
  int port = 0;
  std::unique_ptr<asio::steady_timer> timer;
  std::thread thread;
  Timestamp last_t_ns = 0;
  // A frame has gone out (its time can be 0: the simulator's first frame is at t = 0).
  bool had_frame = false;
  int ticks = 0;
  // Tells a client that reconnects whether this is the server it saw before.
  std::string session_id = std::to_string(std::chrono::system_clock::now().time_since_epoch() /
                                          std::chrono::milliseconds(1));

  mutable std::mutex mu;  // guards the fields below
  std::optional<FrameView> pending;
  bool flush_posted = false;
  ServerStats stats;

  // A line about clients, at most max_log_lines_per_s a second: 200 clients that come at once
  // (or one that reconnects in a loop) get a few lines and a count, not a line each.
  void Log(const std::string& line) {
    if (!options.log) return;
    SummarizeLog(false);
    if (++log_lines_in_window > options.max_log_lines_per_s) {
      ++log_suppressed;
      std::lock_guard<std::mutex> lock(mu);
      ++stats.log_lines_suppressed;
      return;
    }
    options.log("live view: " + line);
  }
  // At the end of each second: the count of the lines not shown in it, in one line.
  void SummarizeLog(bool at_end) {
    if (!at_end && SecondsSince(log_window) < 1.0) return;
    if (log_suppressed > 0)
      options.log("live view: " + std::to_string(log_suppressed) +
                  " more lines about clients not shown (at most " +
                  std::to_string(options.max_log_lines_per_s) + " a second)");
    log_suppressed = 0;
    log_window = Clock::now();
    log_lines_in_window = 0;
  }
  // Logs a kind of bad input once per client (a flood gets one line), 32 kinds at most.
  void Tell(Client& c, const std::string& kind, const std::string& line) {
    if (c.told.size() < 32 && c.told.insert(kind).second) Log(c.name + ": " + line);
  }
  // Every message to a client goes through here: above twice max_buffered_bytes in its queue it
  // is dropped (counted), so that a client that reads nothing cannot grow the process, whatever
  // it asks for (replies to a flood, the route latched again on every subscribe). Images are
  // dropped from max_buffered_bytes (Flush).
  bool SendBounded(Hdl h, const std::string& payload, websocketpp::frame::opcode::value op) {
    std::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
    if (ec) return false;
    if (con->get_buffered_amount() > 2 * options.max_buffered_bytes) {
      std::lock_guard<std::mutex> lock(mu);
      ++stats.messages_dropped;
      return false;
    }
    ws.send(h, payload, op, ec);
    return !ec;
  }
  void SendText(Hdl h, const std::string& text) {
    SendBounded(h, text, websocketpp::frame::opcode::text);
  }
  bool AdmitConnection(Hdl h);
  void CutOff(Hdl h, Client& c, const std::string& why) {
    if (c.cut_off) return;
    c.cut_off = true;
    Log(c.name + ": cut off (" + why + ")");
    {
      std::lock_guard<std::mutex> lock(mu);
      ++stats.clients_cut_off;
    }
    std::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
    if (ec) return;
    con->get_raw_socket().shutdown(asio::ip::tcp::socket::shutdown_both, ec);
    con->get_raw_socket().close(ec);
  }

  bool Validate(Hdl h);
  void Http(Hdl h);
  void Open(Hdl h);
  void Closed(Hdl h);
  void Message(Hdl h, WsServer::message_ptr msg);
  void Flush();
  void Tick();
  void Start();
};

// Each accepted connection, before its handshake: refused (closed at once) when max_connections
// are open already, handshakes under way included (a flood of connections that never finish
// their handshake held buffers until each timed out).
bool Server::Impl::AdmitConnection(Hdl h) {
  connections.erase(std::remove_if(connections.begin(), connections.end(),
                                   [](const Hdl& c) { return c.expired(); }),
                    connections.end());
  if (connections.size() < options.max_connections) {
    connections.push_back(h);
    return true;
  }
  {
    std::lock_guard<std::mutex> lock(mu);
    ++stats.connections_refused;
  }
  Log("a connection refused (" + std::to_string(options.max_connections) + " open already)");
  return false;
}

bool Server::Impl::Validate(Hdl h) {
  WsServer::connection_ptr con = ws.get_con_from_hdl(h);
  const std::string who = con->get_remote_endpoint();
  // Handshakes accepted and not yet open count too (200 at once all passed the check before).
  validated.erase(
      std::remove_if(validated.begin(), validated.end(),
                     [this](const Hdl& v) { return v.expired() || clients.count(v) > 0; }),
      validated.end());
  if (client_count.load() + validated.size() >= options.max_clients) {
    Log(who + ": refused (" + std::to_string(options.max_clients) + " clients already)");
    return false;
  }
  const std::string chosen = ChooseSubprotocol(con->get_requested_subprotocols());
  if (chosen.empty()) {
    Log(who + ": refused (offers neither " + kSubprotocolSdk + " nor " + kSubprotocolV1 + ")");
    return false;
  }
  con->select_subprotocol(chosen);
  validated.push_back(h);
  return true;
}

void Server::Impl::Http(Hdl h) {
  WsServer::connection_ptr con = ws.get_con_from_hdl(h);
  const std::string resource = con->get_resource();
  if (resource == "/" || resource == "/index.html") {
    con->set_status(websocketpp::http::status_code::ok);
    con->append_header("Content-Type", "text/html; charset=utf-8");
    con->append_header("Cache-Control", "no-store");
    // Self-contained: nothing from elsewhere, and no way to send anything but to this server.
    con->append_header("Content-Security-Policy",
                       "default-src 'none'; script-src 'unsafe-inline'; style-src "
                       "'unsafe-inline'; img-src blob: data:; connect-src ws: wss:");
    con->set_body(page);
  } else {
    con->set_status(websocketpp::http::status_code::not_found);
    con->append_header("Content-Type", "text/plain");
    con->set_body("not found: the live view is at /\n");
  }
}

void Server::Impl::Open(Hdl h) {
  WsServer::connection_ptr con = ws.get_con_from_hdl(h);
  Client c;
  c.name = con->get_remote_endpoint() + " (" + con->get_subprotocol() + ")";
  Log(c.name + ": connected");
  clients.emplace(h, std::move(c));
  client_count = clients.size();
  // The greeting a moment after the handshake, not in the same packet: a client that reads the
  // handshake's answer and the next messages in one go (Node's `ws`) emits them before a program
  // that awaits the connection has registered its handlers (mcap-record of ws-protocol-examples
  // then never sees the channels).
  auto greet =
      std::make_shared<asio::steady_timer>(ws.get_io_service(), std::chrono::milliseconds(50));
  // On a loaded host the client may not read its socket for longer than that, and then takes the
  // greeting in the same read as the handshake's answer all the same (mcap-record recorded
  // nothing in one clean-clone run of tests/live/interop.sh, 2026-12-02). So a client that has
  // said nothing a second after its greeting gets it once more: one that missed it subscribes
  // then; one that had it sees its channels advertised again, which the protocol allows.
  auto again = std::make_shared<asio::steady_timer>(ws.get_io_service(),
                                                    std::chrono::milliseconds(50 + 1000));
  greet->async_wait([this, h, greet](const std::error_code& ec) {
    if (ec || clients.find(h) == clients.end()) return;
    SendText(h, ServerInfoJson(options.name, session_id));
    SendText(h, AdvertiseJson(channels));
  });
  again->async_wait([this, h, again](const std::error_code& ec) {
    const auto it = clients.find(h);
    if (ec || it == clients.end() || it->second.heard || it->second.cut_off) return;
    SendText(h, ServerInfoJson(options.name, session_id));
    SendText(h, AdvertiseJson(channels));
  });
}

void Server::Impl::Closed(Hdl h) {
  const auto it = clients.find(h);
  if (it == clients.end()) return;
  Log(it->second.name + ": disconnected");
  clients.erase(it);
  client_count = clients.size();
}

void Server::Impl::Message(Hdl h, WsServer::message_ptr msg) {
  const auto it = clients.find(h);
  if (it == clients.end()) return;
  Client& c = it->second;
  c.heard = true;
  if (c.cut_off) return;
  if (SecondsSince(c.window_start) >= 1.0) {
    c.window_start = Clock::now();
    c.requests_in_window = 0;
  }
  if (++c.requests_in_window > options.max_requests_per_s) {
    CutOff(h, c, "more than " + std::to_string(options.max_requests_per_s) + " messages a second");
    return;
  }
  if (msg->get_opcode() != websocketpp::frame::opcode::text) {
    Tell(c, "binary", "sent a binary message (ignored: the live view takes no data)");
    SendText(h, StatusJson(2, "binary messages are not accepted: the live view is read-only"));
    return;
  }
  const ClientRequest request = ParseClientMessage(msg->get_payload());
  if (request.kind == ClientRequest::Kind::kInvalid ||
      request.kind == ClientRequest::Kind::kUnsupported) {
    Tell(c, request.error, "sent a message that is ignored: " + request.error);
    SendText(h, StatusJson(request.kind == ClientRequest::Kind::kInvalid ? 2 : 1, request.error));
    return;
  }
  for (const std::string& refused : c.subscriptions.Apply(request, channel_ids)) {
    Tell(c, refused.substr(0, refused.find(':')), refused);
    SendText(h, StatusJson(1, refused));
  }
  // Before the first frame, the first frame's messages bring the route.
  if (request.kind != ClientRequest::Kind::kSubscribe || !had_frame) return;
  for (const Outgoing& o : feed->Latched(last_t_ns)) {
    for (const auto& [sub, channel] : request.subscriptions) {
      if (channel != o.channel_id) continue;
      for (const std::uint32_t mine : c.subscriptions.For(channel))
        if (mine == sub)
          SendBounded(h, MessageDataFrame(sub, static_cast<std::uint64_t>(last_t_ns), o.payload),
                      websocketpp::frame::opcode::binary);
    }
  }
}

void Server::Impl::Flush() {
  std::optional<FrameView> frame;
  {
    std::lock_guard<std::mutex> lock(mu);
    frame.swap(pending);
    flush_posted = false;
  }
  if (!frame) return;
  std::vector<Outgoing> messages = feed->Messages(*frame);
  last_t_ns = std::max<Timestamp>(frame->observation.t_ns, 0);
  had_frame = true;
  std::uint64_t sent = 0, dropped = 0;
  const std::string time = TimeFrame(static_cast<std::uint64_t>(last_t_ns));
  for (auto& [h, c] : clients) {
    std::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
    if (ec) continue;
    if (con->get_buffered_amount() > 2 * options.max_buffered_bytes) {
      ++dropped;  // nothing at all for a client this far behind, not even the time
      continue;
    }
    ws.send(h, time, websocketpp::frame::opcode::binary, ec);
    for (const Outgoing& o : messages) {
      for (const std::uint32_t sub : c.subscriptions.For(o.channel_id)) {
        const std::size_t buffered = con->get_buffered_amount();
        if ((IsImageChannel(o.channel_id) && buffered > options.max_buffered_bytes) ||
            buffered > 2 * options.max_buffered_bytes) {
          ++dropped;
          continue;
        }
        ws.send(h, MessageDataFrame(sub, static_cast<std::uint64_t>(last_t_ns), o.payload),
                websocketpp::frame::opcode::binary, ec);
        if (!ec) ++sent;
      }
    }
  }
  std::lock_guard<std::mutex> lock(mu);
  ++stats.frames_sent;
  stats.messages_sent += sent;
  stats.images_dropped += dropped;
}

// Twice a second: clients whose queue stays over the limit are cut off; pings (a client that does
// not answer within the handshake timeout is closed: half-open connections).
void Server::Impl::Tick() {
  std::vector<Hdl> stalled;
  for (auto& [h, c] : clients) {
    std::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
    if (ec) continue;
    if (con->get_buffered_amount() > options.max_buffered_bytes) {
      if (!c.full_since) c.full_since = Clock::now();
      if (SecondsSince(*c.full_since) > options.stall_timeout_s) stalled.push_back(h);
    } else {
      c.full_since.reset();
    }
    if (ticks % 10 == 0) con->ping("", ec);
  }
  ++ticks;
  if (options.log) SummarizeLog(false);
  for (Hdl h : stalled) {
    const auto it = clients.find(h);
    if (it != clients.end())
      CutOff(h, it->second,
             "it read nothing for " + std::to_string(options.stall_timeout_s) + " s");
  }
  timer->expires_after(std::chrono::milliseconds(500));
  timer->async_wait([this](const std::error_code& ec) {
    if (!ec) Tick();
  });
}

void Server::Impl::Start() {
  ws.clear_access_channels(websocketpp::log::alevel::all);
  ws.clear_error_channels(websocketpp::log::elevel::all);
  ws.init_asio();
  ws.set_reuse_addr(true);
  ws.set_max_message_size(options.max_message_bytes);
  ws.set_max_http_body_size(options.max_message_bytes);
  const long handshake_ms = static_cast<long>(options.handshake_timeout_s * 1000);
  ws.set_open_handshake_timeout(handshake_ms);
  ws.set_close_handshake_timeout(1000);
  ws.set_pong_timeout(handshake_ms);
  ws.set_tcp_pre_init_handler([this](Hdl h) {  // accepted, before the handshake is read
    if (AdmitConnection(h)) return;
    std::error_code ec;
    WsServer::connection_ptr con = ws.get_con_from_hdl(h, ec);
    if (ec) return;
    con->get_raw_socket().shutdown(asio::ip::tcp::socket::shutdown_both, ec);
    con->get_raw_socket().close(ec);
  });
  ws.set_validate_handler([this](Hdl h) { return Validate(h); });
  ws.set_http_handler([this](Hdl h) { Http(h); });
  ws.set_open_handler([this](Hdl h) { Open(h); });
  ws.set_close_handler([this](Hdl h) { Closed(h); });
  ws.set_fail_handler([this](Hdl h) { Closed(h); });
  ws.set_message_handler([this](Hdl h, WsServer::message_ptr m) { Message(h, std::move(m)); });
  ws.set_pong_timeout_handler([this](Hdl h, const std::string&) {
    const auto it = clients.find(h);
    if (it != clients.end()) CutOff(h, it->second, "no answer to a ping");
  });
  std::error_code ec;
  const asio::ip::tcp::endpoint endpoint(asio::ip::make_address(options.address.host),
                                         static_cast<unsigned short>(options.address.port));
  ws.listen(endpoint, ec);
  MAPLESS_CHECK(!ec, "--live " << options.address.host << ":" << options.address.port << ": "
                               << ec.message());
  ws.start_accept(ec);
  MAPLESS_CHECK(!ec, "--live: cannot accept connections: " << ec.message());
  port = ws.get_local_endpoint(ec).port();
  timer = std::make_unique<asio::steady_timer>(ws.get_io_service());
  Tick();
  thread = std::thread([this] { ws.run(); });
}

Server::Server(std::vector<Channel> channels, std::unique_ptr<Feed> feed, std::string page,
               ServerOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->channels = std::move(channels);
  for (const Channel& c : impl_->channels) impl_->channel_ids.push_back(c.id);
  impl_->feed = std::move(feed);
  impl_->page = std::move(page);
  impl_->Start();
}

Server::~Server() {
  Impl* impl = impl_.get();
  auto done = std::make_shared<std::promise<void>>();
  asio::post(impl->ws.get_io_service(), [impl, done] {
    std::error_code ec;
    impl->ws.stop_listening(ec);
    impl->timer->cancel();
    for (auto& [h, c] : impl->clients)
      impl->ws.close(h, websocketpp::close::status::going_away, "the run ended", ec);
    if (impl->options.log) impl->SummarizeLog(true);
    done->set_value();
  });
  done->get_future().wait_for(std::chrono::seconds(2));
  // The clients' queues go out before the close frames (a reading client sees the run to its
  // end); a client that reads nothing holds the exit at most 2 s, then the thread stops.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (impl->client_count.load() > 0 && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  impl->ws.stop();
  if (impl->thread.joinable()) impl->thread.join();
}

int Server::port() const { return impl_->port; }
std::size_t Server::clients() const { return impl_->client_count.load(); }

void Server::Offer(FrameView frame) {
  {
    std::lock_guard<std::mutex> lock(impl_->mu);
    ++impl_->stats.frames_offered;
    impl_->pending = std::move(frame);
    if (impl_->flush_posted) return;
    impl_->flush_posted = true;
  }
  Impl* impl = impl_.get();
  asio::post(impl->ws.get_io_service(), [impl] { impl->Flush(); });
}

ServerStats Server::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mu);
  return impl_->stats;
}

}  // namespace mapless::live

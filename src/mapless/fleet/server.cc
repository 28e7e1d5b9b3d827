#include "mapless/fleet/server.h"

#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <zmq.hpp>

#include "mapless/core/check.h"
#include "mapless/fleet/limited_log.h"
#include "mapless/fleet/zmq_util.h"

namespace mapless::fleet {

struct LeaderServer::Impl {
  using Clock = std::chrono::steady_clock;
  struct Peer {
    std::uint64_t next = 0;
    Clock::time_point last_heard;
    Clock::time_point last_sent;
    std::string address;
    // The sizes of the last peer_queue + 1 messages sent: what its queue (and ZeroMQ's message
    // being written) can hold at most, since older messages leave first.
    std::deque<std::size_t> window;
    std::size_t window_bytes = 0;
    int fd = -1;                     // its connection's socket (ZMQ_SRCFD of its last message)
    Clock::time_point full_since{};  // its queue full since then (epoch: not full)
  };
  std::size_t queued_bytes = 0;  // the sum of every peer's window_bytes

  // Whether a message of `bytes` to `peer` keeps all queues together within total_queue_bytes
  // (else the peer is served in a later round); Account() books it once sent.
  bool Affordable(const Peer& peer, std::size_t bytes) const {
    const std::size_t leaving =
        peer.window.size() > static_cast<std::size_t>(options.peer_queue) ? peer.window.front() : 0;
    return bytes <= leaving || queued_bytes - leaving + bytes <= options.total_queue_bytes;
  }
  void Account(Peer& peer, std::size_t bytes) {
    if (peer.window.size() > static_cast<std::size_t>(options.peer_queue)) {
      peer.window_bytes -= peer.window.front();
      queued_bytes -= peer.window.front();
      peer.window.pop_front();
    }
    peer.window.push_back(bytes);
    peer.window_bytes += bytes;
    queued_bytes += bytes;
  }
  std::map<std::string, Peer>::iterator Forget(std::map<std::string, Peer>::iterator it) {
    queued_bytes -= it->second.window_bytes;
    return peers.erase(it);
  }

  const RouteCopy& log;
  ServerOptions options;
  FleetLogger log_line;
  zmq::context_t context{1};
  zmq::socket_t router{context, zmq::socket_type::router};
  zmq::socket_t zap{context, zmq::socket_type::rep};
  zmq::socket_t monitor{context, zmq::socket_type::pair};
  int wake_fd = -1;
  std::string endpoint;
  std::atomic<bool> stop{false};
  mutable std::mutex stats_mutex;
  ServerStats stats;
  std::map<std::string, Peer> peers;  // by ZeroMQ routing id
  std::thread thread;

  Impl(const RouteCopy& l, ServerOptions o, FleetLogger f)
      : log(l), options(std::move(o)), log_line(std::move(f)) {}

  void Log(const std::string& line) {
    if (log_line) log_line(line);
  }

  LimitedLog limited{[this](const std::string& line) { Log(line); }};
  void LogLimited(const std::string& kind, const std::string& line) { limited.Say(kind, line); }

  void Count(std::uint64_t ServerStats::*field) {
    std::lock_guard<std::mutex> lock(stats_mutex);
    ++(stats.*field);
  }

  void HandleZap() {
    std::vector<zmq::message_t> request;
    if (!RecvAll(zap, &request)) return;
    // ZAP 1.0: version, request id, domain, address, identity, mechanism, credentials...
    if (request.size() < 6) return;
    const std::string address = request[3].to_string();
    std::string client_key;
    if (request.size() >= 7 && request[6].size() == 32) {
      char z85[41];
      zmq_z85_encode(z85, static_cast<const std::uint8_t*>(request[6].data()), 32);
      client_key = z85;
    }
    const auto& allowed = options.security.allowed_public;
    const bool ok =
        request[5].to_string() == "CURVE" &&
        (allowed.empty() || std::find(allowed.begin(), allowed.end(), client_key) != allowed.end());
    if (!ok) {
      Count(&ServerStats::refused);
      LogLimited("keys refused", "fleet: refused a follower from " + address + ": its key " +
                                     client_key + " is not admitted (--curve-allow)");
    }
    std::vector<std::string> reply = {
        "1.0", request[1].to_string(), ok ? "200" : "400", ok ? "OK" : "key not admitted", "", ""};
    for (std::size_t i = 0; i < reply.size(); ++i) {
      zap.send(zmq::buffer(reply[i]),
               i + 1 < reply.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
    }
  }

  // Connections by socket, from accepted until the handshake succeeded or failed: one that closes
  // in between was refused (garbage, or a peer that is not a mapless follower).
  std::map<std::uint32_t, bool> pending_handshakes;

  void HandleMonitor() {
    std::vector<zmq::message_t> event;
    if (!RecvAll(monitor, &event) || event.size() < 2 || event[0].size() < 6) return;
    std::uint16_t id = 0;
    std::uint32_t fd = 0;
    std::memcpy(&id, event[0].data(), 2);
    std::memcpy(&fd, static_cast<const char*>(event[0].data()) + 2, 4);
    const std::string where = event[1].to_string();
    if (id == ZMQ_EVENT_ACCEPTED) {
      pending_handshakes[fd] = true;
    } else if (id == ZMQ_EVENT_HANDSHAKE_SUCCEEDED) {
      pending_handshakes.erase(fd);
    } else if (id == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) {
      pending_handshakes.erase(fd);  // logged by the ZAP handler
    } else if (id == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL ||
               id == ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL ||
               (id == ZMQ_EVENT_DISCONNECTED && pending_handshakes.count(fd))) {
      pending_handshakes.erase(fd);
      Count(&ServerStats::refused);
      LogLimited("connections refused",
                 "fleet: refused a connection on " + where +
                     ": the handshake failed (not a mapless follower, or one without the "
                     "leader's CURVE key)");
    }
  }

  void HandleRouter() {
    while (true) {
      std::vector<zmq::message_t> msg;
      if (!RecvAll(router, &msg, /*wait=*/false)) return;
      if (msg.size() != 2) {
        Count(&ServerStats::rejected);
        LogLimited("messages rejected",
                   "fleet: rejected a message of " + std::to_string(msg.size()) + " frames");
        continue;
      }
      const std::string id = msg[0].to_string();
      if (msg[1].size() >= 4 && std::memcmp(msg[1].data(), "MLFR", 4) == 0) {
        TakeView(msg[1].to_string_view());
        continue;
      }
      std::uint64_t from = 0;
      try {
        from = DecodeSubscribe(msg[1].to_string_view());
      } catch (const InputError& e) {
        Count(&ServerStats::rejected);
        LogLimited("messages rejected",
                   std::string("fleet: rejected a message from a follower: ") + e.what());
        continue;
      }
      Count(&ServerStats::subscriptions);
      const bool known = peers.count(id) > 0;
      if (!known && static_cast<int>(peers.size()) >= options.max_followers) {
        Count(&ServerStats::turned_away);
        LogLimited("followers turned away",
                   "fleet: turned a follower away: " + std::to_string(peers.size()) +
                       " are served already (the leader's limit)");
        continue;
      }
      Peer& peer = peers[id];
      if (!known) {
        const char* address = msg[1].gets("Peer-Address");
        peer.address = address ? address : "?";
        LogLimited("followers joined", "fleet: a follower at " + peer.address +
                                           " asks for the route from record " +
                                           std::to_string(from));
      }
      peer.fd = msg[1].get(ZMQ_SRCFD);
      if (known && from == peer.next) {
        // It has every record sent to it: nothing of ours is left in its queue.
        queued_bytes -= peer.window_bytes;
        peer.window.clear();
        peer.window_bytes = 0;
      }
      peer.next = from;
      peer.last_heard = Clock::now();
    }
  }

  // A view a follower offers (a record of type kView): into the route when the leader takes views.
  void TakeView(std::string_view bytes) {
    try {
      if (!options.take_view)
        throw InputError("this leader takes no views (mapless lead --take-views)");
      const Record offered = DecodeRecord(bytes);
      if (offered.type != RecordType::kView)
        throw InputError(std::string("a follower sent a ") + RecordTypeName(offered.type) +
                         " record; it may offer views only");
      const std::string line = options.take_view(offered);
      Count(&ServerStats::views_taken);
      LogLimited("views taken", "fleet: " + line);
    } catch (const InputError& e) {
      Count(&ServerStats::views_refused);
      LogLimited("views refused", std::string("fleet: refused a view: ") + e.what());
    }
  }

  // Sends what each follower lacks; true when some follower's pipe is full (retry soon).
  bool SendRound() {
    bool blocked = false;
    bool budget_full = false;
    const std::uint64_t size = log.next_sequence();
    const auto now = Clock::now();
    for (auto it = peers.begin(); it != peers.end();) {
      Peer& peer = it->second;
      if (now - peer.last_heard > std::chrono::duration<double>(options.forget_after_s)) {
        it = Forget(it);
        continue;
      }
      // Records are taken from the log one at a time while the follower's pipe takes them, each
      // encoded once (RouteCopy::Encoded) and queued without a copy for every follower.
      SendResult result = SendResult::kSent;
      std::size_t sent = 0;
      while (peer.next < size && sent < options.batch) {
        const std::shared_ptr<const std::string> bytes = log.Encoded(peer.next);
        if (!bytes) break;
        if (!Affordable(peer, bytes->size())) {
          result = SendResult::kFull;  // the queues together are full: later
          budget_full = true;
          break;
        }
        result = SendTo(router, it->first, bytes);
        if (result != SendResult::kSent) break;
        Account(peer, bytes->size());
        peer.full_since = {};
        ++peer.next;
        ++sent;
        peer.last_sent = now;
      }
      if (sent > 0) {
        std::lock_guard<std::mutex> lock(stats_mutex);
        stats.records_sent += sent;
      }
      if (result == SendResult::kSent && peer.next >= size &&
          now - peer.last_sent >= std::chrono::duration<double>(options.heartbeat_s)) {
        Record beat;  // does not advance peer.next
        beat.type = RecordType::kHeartbeat;
        beat.sequence = size;
        beat.parts = {log.complete() ? "1" : "0"};
        const std::string bytes = EncodeRecord(beat);
        if (Affordable(peer, bytes.size())) {
          result = SendTo(router, it->first, bytes);
          if (result == SendResult::kSent) {
            peer.last_sent = now;
            Account(peer, bytes.size());
          }
        }
      }
      if (result == SendResult::kFull && peer.full_since == Clock::time_point{} &&
          peer.window.size() > static_cast<std::size_t>(options.peer_queue))
        peer.full_since = now;  // its own queue is full (not the total)
      if (peer.full_since != Clock::time_point{} &&
          now - peer.full_since > std::chrono::duration<double>(options.stall_drop_s)) {
        // It has not taken a record for stall_drop_s: it stopped reading. Its connection is
        // closed (ZeroMQ's ROUTER has no call for that, so its socket is shut down: ZeroMQ then
        // closes the session and frees the queue); it may connect and ask again.
        Count(&ServerStats::dropped);
        LogLimited("followers dropped", "fleet: dropped the follower at " + peer.address +
                                            " at record " + std::to_string(peer.next) + " of " +
                                            std::to_string(size) + ": it read nothing for " +
                                            std::to_string(static_cast<int>(options.stall_drop_s)) +
                                            " s");
        if (peer.fd >= 0) ::shutdown(peer.fd, SHUT_RDWR);
        it = Forget(it);
        continue;
      }
      blocked = blocked || result == SendResult::kFull;
      if (result == SendResult::kGone) {
        // Its connection closed: it left, or stopped reading and missed the heartbeats.
        if (peer.next < size) {
          Count(&ServerStats::dropped);
          LogLimited("followers dropped",
                     "fleet: dropped the follower at " + peer.address + " at record " +
                         std::to_string(peer.next) + " of " + std::to_string(size) +
                         ": its connection closed (it left, or stopped reading)");
        }
        it = Forget(it);
        continue;
      }
      ++it;
    }
    if (budget_full) DropSilentPeers(now);
    std::lock_guard<std::mutex> lock(stats_mutex);
    stats.followers = static_cast<int>(peers.size());
    stats.queued_bytes = queued_bytes;
    return blocked;
  }

  // The queues together are full: a follower that reads asks again within resubscribe_s when the
  // leader falls silent (and then its queue is known to be empty), so one not heard from for
  // stall_drop_s with records queued has stopped reading, even if its own queue never filled (the
  // total filled first). It is dropped, as a full queue's follower is, so that the others move.
  void DropSilentPeers(Clock::time_point now) {
    for (auto it = peers.begin(); it != peers.end();) {
      Peer& peer = it->second;
      if (peer.window.empty() ||
          now - peer.last_heard <= std::chrono::duration<double>(options.stall_drop_s)) {
        ++it;
        continue;
      }
      Count(&ServerStats::dropped);
      LogLimited("followers dropped", "fleet: dropped the follower at " + peer.address +
                                          " at record " + std::to_string(peer.next) +
                                          ": nothing heard from it for " +
                                          std::to_string(static_cast<int>(options.stall_drop_s)) +
                                          " s while the leader's queues were full");
      if (peer.fd >= 0) ::shutdown(peer.fd, SHUT_RDWR);
      it = Forget(it);
    }
  }

  void Run() {
    bool blocked = false;
    while (!stop) {
      std::vector<zmq::pollitem_t> items = {{router.handle(), 0, ZMQ_POLLIN, 0},
                                            {nullptr, wake_fd, ZMQ_POLLIN, 0},
                                            {monitor.handle(), 0, ZMQ_POLLIN, 0}};
      if (options.security.enabled()) items.push_back({zap.handle(), 0, ZMQ_POLLIN, 0});
      zmq::poll(items, std::chrono::milliseconds(blocked ? 2 : 100));
      if (items[1].revents & ZMQ_POLLIN) {
        std::uint64_t n = 0;
        if (::read(wake_fd, &n, sizeof(n)) < 0) n = 0;
      }
      if (stop) break;
      if (items[0].revents & ZMQ_POLLIN) HandleRouter();
      if (items[2].revents & ZMQ_POLLIN) HandleMonitor();
      if (items.size() > 3 && (items[3].revents & ZMQ_POLLIN)) HandleZap();
      blocked = SendRound();
      limited.Flush();
    }
  }
};

LeaderServer::LeaderServer(const RouteCopy& log, ServerOptions options, FleetLogger log_line)
    : impl_(std::make_unique<Impl>(log, std::move(options), std::move(log_line))) {
  Impl& s = *impl_;
  CheckEndpoint(s.options.bind, "--bind", /*bind=*/true);
  s.wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  MAPLESS_CHECK(s.wake_fd >= 0, "fleet: cannot create an eventfd");
  try {
    if (s.options.security.enabled()) {
      MAPLESS_CHECK(CurveAvailable(), "fleet: this libzmq was built without CURVE (libsodium)");
      s.zap.bind("inproc://zeromq.zap.01");
      s.router.set(zmq::sockopt::curve_server, 1);
      s.router.set(zmq::sockopt::curve_secretkey, s.options.security.key.secret_key);
      s.router.set(zmq::sockopt::zap_domain, "mapless");
    }
    s.router.set(zmq::sockopt::router_mandatory, 1);
    // Subscriptions are 16 bytes: a larger message still reaches the decoder (and its log line) up
    // to 64 KiB; beyond that ZeroMQ drops the connection. A leader that takes views takes messages
    // up to kMaxViewOfferBytes (a view of 500 ORB features is about 100 KB), 8 queued a follower.
    if (s.options.take_view) {
      s.router.set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(kMaxViewOfferBytes));
      s.router.set(zmq::sockopt::rcvhwm, 8);
    } else {
      s.router.set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(64 << 10));
    }
    MAPLESS_CHECK(s.options.peer_queue >= 1 && s.options.max_followers >= 1,
                  "fleet: peer_queue and max_followers must be >= 1");
    s.router.set(zmq::sockopt::sndhwm, s.options.peer_queue);
    s.router.set(zmq::sockopt::linger, 200);
    SetHeartbeats(s.router);
    zmq_socket_monitor(s.router.handle(), "inproc://mapless-fleet-monitor",
                       ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL | ZMQ_EVENT_HANDSHAKE_FAILED_AUTH |
                           ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL | ZMQ_EVENT_ACCEPTED |
                           ZMQ_EVENT_HANDSHAKE_SUCCEEDED | ZMQ_EVENT_DISCONNECTED);
    s.monitor.connect("inproc://mapless-fleet-monitor");
    s.router.bind(s.options.bind);
    s.endpoint = s.router.get(zmq::sockopt::last_endpoint);
  } catch (const zmq::error_t& e) {
    ::close(s.wake_fd);
    throw InputError("--bind " + s.options.bind + ": " + e.what());
  }
  s.thread = std::thread([&s] { s.Run(); });
}

LeaderServer::~LeaderServer() {
  impl_->stop = true;
  Notify();
  if (impl_->thread.joinable()) impl_->thread.join();
  ::close(impl_->wake_fd);
}

void LeaderServer::Notify() {
  const std::uint64_t one = 1;
  if (::write(impl_->wake_fd, &one, sizeof(one)) < 0) {
    // The counter is saturated: the thread is awake anyway.
  }
}

std::string LeaderServer::endpoint() const { return impl_->endpoint; }

ServerStats LeaderServer::stats() const {
  std::lock_guard<std::mutex> lock(impl_->stats_mutex);
  return impl_->stats;
}

}  // namespace mapless::fleet

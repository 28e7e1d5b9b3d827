// The leader's side of the fleet link: serves its route log (route_log.h) to any number of
// followers over ZeroMQ (a ROUTER socket; TCP between machines, ipc:// or loopback on one).
//
// A follower says "from sequence n" (record.h); the leader sends it the records from n on, as fast
// as the follower's connection takes them (ZeroMQ's high-water mark; nothing is dropped: a full
// pipe is retried), then each new record as the teach appends it. A follower that says "from n"
// again (it reconnected, or saw a gap) is served from n again. When a follower is up to date the
// leader sends it a heartbeat every second with the number of records in the log, so the follower
// knows the leader is there and whether it has everything.
//
// Runs its own thread; Notify() wakes it when a record was appended. With CURVE keys (curve.h) a
// follower without the leader's public key, or with a key not admitted, gets nothing, and the
// refusal is logged.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "mapless/fleet/curve.h"
#include "mapless/fleet/route_log.h"

namespace mapless::fleet {

using FleetLogger = std::function<void(const std::string&)>;

// The bounds on what the network can make the leader hold (docs/hardening.md). A follower that
// does not read fills its queue (peer_queue messages): after stall_drop_s it is dropped (its
// connection closed) with a line; all queues together are held under
// total_queue_bytes (a follower is served later rather than memory grown; while they are full, a
// follower not heard from for stall_drop_s with records queued is dropped too: one that reads
// asks again when the leader falls silent), and at most max_followers are served at once (one
// more is told nothing and logged).
// The largest view a follower may offer, encoded (ServerOptions::take_view).
inline constexpr std::size_t kMaxViewOfferBytes = std::size_t{1} << 20;

struct ServerOptions {
  std::string bind = "tcp://127.0.0.1:5600";
  LeaderSecurity security;
  std::size_t batch = 256;       // records per follower per round
  double heartbeat_s = 1.0;      // to an up-to-date follower
  double forget_after_s = 60.0;  // a follower silent this long is forgotten (it resubscribes)
  int peer_queue = 8;            // messages queued to one follower (ZMQ_SNDHWM)
  std::size_t total_queue_bytes = std::size_t{96} << 20;  // queued to all followers together
  int max_followers = 256;
  double stall_drop_s = 10.0;  // a follower whose queue stayed full this long is dropped
  // Views followers offer (issue 45; route_log.h): taken by this (RouteCopy::TakeView, which
  // throws InputError saying why it refuses one; it returns a line for the log). Empty: the
  // leader takes none, and says so once a second at most. Only followers the leader admits
  // offer anything (with CURVE, only admitted keys).
  std::function<std::string(const Record&)> take_view;
};

struct ServerStats {
  std::uint64_t subscriptions = 0;  // "from n" messages taken
  std::uint64_t records_sent = 0;
  std::uint64_t refused = 0;      // handshakes failed or keys not admitted
  std::uint64_t rejected = 0;     // malformed messages
  std::uint64_t dropped = 0;      // followers that stopped reading (or left) while records were due
  std::uint64_t turned_away = 0;  // subscriptions beyond max_followers
  std::uint64_t views_taken = 0;  // views followers offered, taken into the route
  std::uint64_t views_refused = 0;
  int followers = 0;  // known now
  std::size_t queued_bytes =
      0;  // the bound on what the queues hold now (at most total_queue_bytes)
};

class LeaderServer {
 public:
  // Binds (throws InputError naming the endpoint when it cannot) and starts serving `log`, which
  // must outlive the server.
  LeaderServer(const RouteCopy& log, ServerOptions options, FleetLogger log_line);
  ~LeaderServer();
  void Notify();                 // a record was appended to the log
  std::string endpoint() const;  // as bound (a tcp port 0 / "*" resolved)
  ServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mapless::fleet

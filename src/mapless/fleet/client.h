// The follower's side of the fleet link: keeps a local copy of the leader's route (RouteCopy) in
// step with the leader's log over ZeroMQ (a DEALER socket).
//
// The follower asks for the records from its copy's next sequence number on; applies each record
// only when it is the next one (an older one is a duplicate and is dropped, a newer one means a
// gap: it is dropped and the follower asks again from the number it needs), so nothing is applied
// twice and nothing is skipped. When the leader has been silent for resubscribe_s (it sends a
// heartbeat every second), the follower asks again: after a link outage, a leader restart or a
// follower restart, the copy goes on from its last whole record.
//
// Runs its own threads. A malformed record is rejected with one log line (at most one a second of
// each kind, with counts) and changes nothing. What it holds is bounded: 32 messages in ZeroMQ's
// queue, 1,024 records waiting to be applied.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mapless/fleet/curve.h"
#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"

namespace mapless::fleet {

struct ClientOptions {
  std::string connect = "tcp://127.0.0.1:5600";
  FollowerSecurity security;
  double resubscribe_s = 2.0;
  std::size_t max_batch = 256;  // records applied (and flushed to disk) together
};

struct ClientStats {
  std::uint64_t received = 0;            // records taken off the link
  std::uint64_t applied = 0;             // ... and applied to the copy (each exactly once)
  std::uint64_t duplicates_dropped = 0;  // older than the next one needed (sent again)
  std::uint64_t ahead_dropped = 0;       // newer than the next one needed (a gap, asked again)
  std::uint64_t rejected = 0;            // malformed or refused by the copy
  std::uint64_t subscriptions = 0;       // "from n" sent
  std::uint64_t views_offered = 0;       // learned views sent to the leader (Share)
  std::uint64_t leader_records = 0;      // the leader's log size at its last heartbeat
  bool leader_complete = false;
  double silent_s = 0.0;           // since the last message from the leader
  std::string link_state;          // what the connection is doing ("no connection to ...")
  std::vector<double> latency_ms;  // live records: leader's write to this receive
};

// The counts of a follower's link for its summary (`follow --connect --summary`): records_received,
// records_applied, duplicates_dropped, ahead_dropped, rejected, subscriptions, latency_samples,
// latency_median_ms and latency_p99_ms (-1 without live records: the route was finished).
nlohmann::json ClientStatsJson(const ClientStats& stats);

class FollowerClient {
 public:
  // `copy` must outlive the client.
  FollowerClient(RouteCopy& copy, ClientOptions options, FleetLogger log_line);
  ~FollowerClient();
  ClientStats stats() const;
  // Not empty when this follower cannot go on with this leader, and why: its copy (resumed from
  // disk) is of another route, the leader refused its CURVE key, the handshake failed three times
  // in a row, or the link's thread stopped. It then takes nothing more.
  std::string Refusal() const;
  // Offers the leader views this follower's repeat learned (ShareViewRecord records, issue 45);
  // sent by the link's thread as the connection takes them (at most 1,024 waiting; more are
  // dropped with a line). The leader that takes one appends it to the route, and it comes back to
  // this copy as a record like every other.
  void Share(std::vector<Record> views);
  // True once the copy is known to be the leader's route: at once for a new copy; for one resumed
  // from disk, when the leader's copy of its last record matched.
  bool Verified() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mapless::fleet

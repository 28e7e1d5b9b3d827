#include "mapless/fleet/client.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>
#include <zmq.hpp>

#include "mapless/core/check.h"
#include "mapless/fleet/limited_log.h"
#include "mapless/fleet/zmq_util.h"

namespace mapless::fleet {

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kMaxLatencySamples = 100000;
// Records received and not yet applied: beyond this the follower takes no more until the copy
// has caught up (the leader sends them again when asked), so a leader cannot fill its memory.
constexpr std::size_t kMaxQueuedRecords = 1024;
// Handshakes failed in a row before the follower gives up on a leader it has never completed a
// handshake with: the two disagree on CURVE (a key on one side only, the wrong leader key) or the
// endpoint is not a mapless leader. Once one handshake has succeeded the keys are known to agree,
// and failures are the way to the leader (a proxy whose leader is down or restarting): the
// follower keeps trying and says so.
constexpr int kMaxHandshakeFailures = 3;

}  // namespace

// Two threads: the network thread takes messages off the socket as they arrive (stamping the
// receive time, so a record's latency does not include the previous record's disk flush) and
// queues the records that continue the copy; the apply thread writes them to the copy in batches.
struct FollowerClient::Impl {
  RouteCopy& copy;
  ClientOptions options;
  FleetLogger log_line;
  zmq::context_t context{1};
  zmq::socket_t dealer{context, zmq::socket_type::dealer};
  zmq::socket_t monitor{context, zmq::socket_type::pair};
  std::atomic<bool> stop{false};
  mutable std::mutex stats_mutex;
  ClientStats stats;
  // Network thread only.
  Clock::time_point last_heard = Clock::now();
  Clock::time_point last_subscribe;
  Clock::time_point hold_until;  // after a refused record: ask again no sooner than this
  std::int64_t first_subscribe_ns = 0;
  std::uint64_t expected = 0;   // the next sequence number to queue
  bool verify_pending = false;  // the copy's last record not yet compared with the leader's
  bool verified = false;        // under stats_mutex: the copy is the leader's route (so far)
  bool unsent = false;          // the last subscription found no connection
  // Between the two threads.
  std::mutex queue_mutex;
  std::condition_variable queue_ready;
  std::deque<Record> queue;
  std::atomic<std::size_t> queued{0};  // queue.size()
  std::atomic<bool> resync{false};     // a record was refused: drop the queue, ask from the copy
  std::string refusal;                 // under stats_mutex: why this follower takes nothing more
  std::deque<std::string> outbox;      // under queue_mutex: views to offer the leader, encoded
  std::string refused() {
    std::lock_guard<std::mutex> lock(stats_mutex);
    return refusal;
  }
  // Apply thread only.
  std::uint64_t rejected_sequence = ~0ull;  // log a bad record once, not at every resend
  std::thread network;
  std::thread applier;

  Impl(RouteCopy& c, ClientOptions o, FleetLogger f)
      : copy(c), options(std::move(o)), log_line(std::move(f)) {}

  void Log(const std::string& line) {
    if (log_line) log_line(line);
  }
  LimitedLog limited{[this](const std::string& line) { Log(line); }};  // network thread

  // The connection as ZeroMQ's monitor tells it (network thread): what the follower waits for.
  int handshake_failures = 0;
  bool handshaking = false;      // connected, handshake not yet succeeded or failed
  bool handshake_known = false;  // a handshake with this leader has succeeded
  void CountHandshakeFailure() {
    handshaking = false;
    ++handshake_failures;
    if (handshake_known) {
      // Said at the 1st, 10th, 100th ... failure in a row: a leader down for an hour is not an
      // hour of lines (the link state, said every 5 s, has the rest).
      const int n = handshake_failures;
      if (n == 1 || n == 10 || n == 100 || n == 1000 || n % 10000 == 0) {
        Log("fleet: the handshake with " + options.connect + " failed " + std::to_string(n) +
            (n == 1 ? " time" : " times") +
            " in a row since the link was last up (the leader restarting, a proxy with nothing "
            "behind it, or a leader with other CURVE keys?); trying again");
      }
      return;
    }
    if (handshake_failures < kMaxHandshakeFailures) return;
    Refuse("the handshake with " + options.connect + " failed " +
           std::to_string(handshake_failures) +
           " times: the leader and this follower disagree on CURVE (--curve-key on one side only, "
           "or not the leader's public key in --curve-leader), or no mapless leader listens there");
  }
  void Refuse(const std::string& why) {
    std::lock_guard<std::mutex> lock(stats_mutex);
    if (!refusal.empty()) return;
    refusal = why;
    Log("fleet: " + why);
  }
  void SetLinkState(const std::string& state) {
    std::lock_guard<std::mutex> lock(stats_mutex);
    stats.link_state = state;
  }
  void HandleMonitor() {
    std::vector<zmq::message_t> event;
    if (!RecvAll(monitor, &event, /*wait=*/false) || event.size() < 2 || event[0].size() < 6)
      return;
    std::uint16_t id = 0;
    std::uint32_t value = 0;
    std::memcpy(&id, event[0].data(), 2);
    std::memcpy(&value, static_cast<const char*>(event[0].data()) + 2, 4);
    const std::string& at = options.connect;
    switch (id) {
      case ZMQ_EVENT_CONNECT_RETRIED:
        SetLinkState("no connection to " + at + " (nothing listens there yet?)");
        break;
      case ZMQ_EVENT_CONNECTED:
        handshaking = true;
        SetLinkState("connected to " + at + ", handshake under way");
        break;
      case ZMQ_EVENT_HANDSHAKE_SUCCEEDED:
        handshaking = false;
        handshake_failures = 0;
        handshake_known = true;
        SetLinkState("connected to " + at);
        break;
      case ZMQ_EVENT_HANDSHAKE_FAILED_AUTH:
        handshaking = false;
        Refuse("the leader at " + at + " refused this follower's CURVE key (status " +
               std::to_string(value) + "; is its public key among the leader's --curve-allow?)");
        break;
      case ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL:
        // Not transient (ZeroMQ may not even dial again): the two speak different protocols, a
        // CURVE key on one side only being the usual reason.
        handshaking = false;
        Refuse(
            "the handshake with " + at + " failed: " +
            (value == ZMQ_PROTOCOL_ERROR_ZMTP_MECHANISM_MISMATCH
                 ? std::string("one side uses CURVE keys and the other does not (give "
                               "--curve-key and --curve-leader to both, or to neither)")
                 : "protocol error " + std::to_string(value) + " (not a mapless leader there?)"));
        break;
      case ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL:
        if (handshaking) CountHandshakeFailure();
        SetLinkState("the handshake with " + at + " failed");
        break;
      case ZMQ_EVENT_DISCONNECTED:
        // Closed before the handshake succeeded: the leader refused it (CURVE on one side only
        // shows so, or as a protocol failure).
        if (handshaking) CountHandshakeFailure();
        SetLinkState("disconnected from " + at + ", reconnecting");
        break;
      default:
        break;
    }
  }

  // With ZMQ_IMMEDIATE a message is not queued while there is no connection: nothing was sent,
  // and the next round tries again.
  // A copy resumed from disk asks for its own last record once more and compares it with what the
  // leader sends: a copy of another route (a directory reused) is refused, not continued.
  void Subscribe() {
    const std::string msg = EncodeSubscribe(verify_pending ? expected - 1 : expected);
    if (!dealer.send(zmq::buffer(msg), zmq::send_flags::dontwait)) {
      unsent = true;
      return;
    }
    unsent = false;
    last_subscribe = Clock::now();
    if (first_subscribe_ns == 0) first_subscribe_ns = WallClockNs();
    std::lock_guard<std::mutex> lock(stats_mutex);
    ++stats.subscriptions;
  }

  // Takes the waiting messages and queues the records that continue the copy; true when a gap was
  // seen (ask again).
  bool Receive() {
    bool gap = false;
    std::vector<Record> taken;
    while (true) {
      zmq::message_t msg;
      if (!dealer.recv(msg, zmq::recv_flags::dontwait)) break;
      const std::int64_t now_ns = WallClockNs();
      last_heard = Clock::now();
      Record r;
      try {
        r = DecodeRecord(msg.to_string_view());
      } catch (const InputError& e) {
        {
          std::lock_guard<std::mutex> lock(stats_mutex);
          ++stats.rejected;
        }
        limited.Say("messages rejected",
                    std::string("fleet: rejected a message from the leader: ") + e.what());
        continue;
      }
      std::lock_guard<std::mutex> lock(stats_mutex);
      if (!refusal.empty()) continue;
      if (r.type == RecordType::kHeartbeat) {
        stats.leader_records = r.sequence;
        stats.leader_complete = r.parts[0] == "1";
        if (r.sequence > expected) gap = true;  // the leader has more than this follower: ask
        continue;
      }
      ++stats.received;
      if (verify_pending && r.sequence + 1 == expected) {
        verify_pending = false;
        const std::vector<Record> mine = copy.RecordsFrom(r.sequence, 1);
        if (mine.empty() || !(mine[0] == r)) {
          refusal = "the copy in " + copy.dir() +
                    " is of another route than the leader's (record " + std::to_string(r.sequence) +
                    " differs); follow into a new directory";
          Log("fleet: " + refusal);
        } else {
          verified = true;
        }
        continue;
      }
      if (r.sequence < expected) {
        ++stats.duplicates_dropped;
        continue;
      }
      if (r.sequence > expected || queued + taken.size() >= kMaxQueuedRecords) {
        ++stats.ahead_dropped;  // a gap, or the copy is behind: asked again later
        gap = true;
        continue;
      }
      if (r.written_ns >= first_subscribe_ns && stats.latency_ms.size() < kMaxLatencySamples)
        stats.latency_ms.push_back(static_cast<double>(now_ns - r.written_ns) * 1e-6);
      taken.push_back(std::move(r));
      ++expected;
    }
    if (!taken.empty()) {
      std::lock_guard<std::mutex> lock(queue_mutex);
      for (Record& r : taken) queue.push_back(std::move(r));
      queued = queue.size();
      queue_ready.notify_one();
    }
    return gap;
  }

  // The views waiting to be offered, as far as the connection takes them now.
  void SendOutbox() {
    std::uint64_t sent = 0;
    {
      std::lock_guard<std::mutex> lock(queue_mutex);
      while (!outbox.empty() &&
             dealer.send(zmq::buffer(outbox.front()), zmq::send_flags::dontwait)) {
        outbox.pop_front();
        ++sent;
      }
    }
    if (sent == 0) return;
    std::lock_guard<std::mutex> lock(stats_mutex);
    stats.views_offered += sent;
  }

  void RunNetwork() {
    expected = copy.next_sequence();
    verify_pending = expected > 0;
    {
      std::lock_guard<std::mutex> lock(stats_mutex);
      verified = !verify_pending;
    }
    Subscribe();
    while (!stop) {
      if (!refused().empty()) {  // nothing more from a leader whose route this is not
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        continue;
      }
      zmq::pollitem_t items[2] = {{dealer.handle(), 0, ZMQ_POLLIN, 0},
                                  {monitor.handle(), 0, ZMQ_POLLIN, 0}};
      zmq::poll(items, 2, std::chrono::milliseconds(unsent ? 20 : 100));
      if (stop) break;
      if (items[1].revents & ZMQ_POLLIN) HandleMonitor();
      limited.Flush();
      const zmq::pollitem_t& item = items[0];
      const auto now = Clock::now();
      if (resync.exchange(false)) {
        std::lock_guard<std::mutex> lock(queue_mutex);
        queue.clear();
        queued = 0;
        expected = copy.next_sequence();
        hold_until = now + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(options.resubscribe_s));
      }
      SendOutbox();
      bool gap = false;
      if (item.revents & ZMQ_POLLIN) gap = Receive();
      const double silent = std::chrono::duration<double>(now - last_heard).count();
      const double since_ask = std::chrono::duration<double>(now - last_subscribe).count();
      if (now >= hold_until &&
          (unsent || (gap && since_ask > 0.2) ||
           (silent > options.resubscribe_s && since_ask > options.resubscribe_s)))
        Subscribe();
      std::lock_guard<std::mutex> lock(stats_mutex);
      stats.silent_s = silent;
    }
  }

  void RunApplier() {
    while (true) {
      std::vector<Record> batch;
      {
        std::unique_lock<std::mutex> lock(queue_mutex);
        queue_ready.wait(lock, [&] { return stop || !queue.empty(); });
        if (stop) return;
        // Catching up, more records are on their way: wait a moment for them, so that many are
        // written with one flush (a live record, alone, is applied at once).
        if (queue.size() < options.max_batch)
          queue_ready.wait_for(lock, std::chrono::milliseconds(2),
                               [&] { return stop || queue.size() >= options.max_batch; });
        while (!queue.empty() && batch.size() < options.max_batch) {
          batch.push_back(std::move(queue.front()));
          queue.pop_front();
        }
        queued = queue.size();
      }
      const std::uint64_t before = copy.next_sequence();
      try {
        copy.Apply(batch);
      } catch (const InputError& e) {
        const std::uint64_t bad = copy.next_sequence();
        if (bad != rejected_sequence)
          Log(std::string("fleet: rejected a record from the leader: ") + e.what());
        rejected_sequence = bad;
        resync = true;
        std::lock_guard<std::mutex> lock(stats_mutex);
        ++stats.rejected;
      }
      std::lock_guard<std::mutex> lock(stats_mutex);
      stats.applied += copy.next_sequence() - before;
    }
  }
};

FollowerClient::FollowerClient(RouteCopy& copy, ClientOptions options, FleetLogger log_line)
    : impl_(std::make_unique<Impl>(copy, std::move(options), std::move(log_line))) {
  Impl& c = *impl_;
  CheckEndpoint(c.options.connect, "--connect", /*bind=*/false);
  try {
    if (c.options.security.enabled()) {
      MAPLESS_CHECK(CurveAvailable(), "fleet: this libzmq was built without CURVE (libsodium)");
      c.dealer.set(zmq::sockopt::curve_serverkey, c.options.security.leader_public);
      c.dealer.set(zmq::sockopt::curve_publickey, c.options.security.key.public_key);
      c.dealer.set(zmq::sockopt::curve_secretkey, c.options.security.key.secret_key);
    }
    c.dealer.set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(kMaxMessageBytes));
    // At most 32 messages wait in ZeroMQ's queue (1,000 by default: 32 GB of maximal records).
    c.dealer.set(zmq::sockopt::rcvhwm, 32);
    c.dealer.set(zmq::sockopt::immediate, 1);
    c.dealer.set(zmq::sockopt::linger, 0);
    c.dealer.set(zmq::sockopt::reconnect_ivl, 200);
    c.dealer.set(zmq::sockopt::reconnect_ivl_max, 1000);
    SetHeartbeats(c.dealer);
    const std::string monitor_endpoint =
        "inproc://mapless-follower-monitor-" + std::to_string(reinterpret_cast<std::uintptr_t>(&c));
    zmq_socket_monitor(c.dealer.handle(), monitor_endpoint.c_str(),
                       ZMQ_EVENT_CONNECTED | ZMQ_EVENT_CONNECT_RETRIED |
                           ZMQ_EVENT_HANDSHAKE_SUCCEEDED | ZMQ_EVENT_HANDSHAKE_FAILED_AUTH |
                           ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                           ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL | ZMQ_EVENT_DISCONNECTED);
    c.monitor.connect(monitor_endpoint);
    c.dealer.connect(c.options.connect);
  } catch (const zmq::error_t& e) {
    throw InputError("--connect " + c.options.connect + ": " + e.what());
  }
  c.network = std::thread([&c] {
    try {
      c.RunNetwork();
    } catch (const std::exception& e) {
      c.Refuse(std::string("the link to the leader stopped: ") + e.what());
    }
  });
  c.applier = std::thread([&c] {
    try {
      c.RunApplier();
    } catch (const std::exception& e) {
      c.Refuse(std::string("the copy of the route stopped: ") + e.what());
    }
  });
}

FollowerClient::~FollowerClient() {
  impl_->stop = true;
  {
    std::lock_guard<std::mutex> lock(impl_->queue_mutex);
    impl_->queue_ready.notify_all();
  }
  if (impl_->network.joinable()) impl_->network.join();
  if (impl_->applier.joinable()) impl_->applier.join();
}

void FollowerClient::Share(std::vector<Record> views) {
  constexpr std::size_t kMaxOutbox = 1024;
  std::size_t dropped = 0;
  std::size_t too_large = 0;
  {
    std::lock_guard<std::mutex> lock(impl_->queue_mutex);
    for (Record& r : views) {
      MAPLESS_CHECK(r.type == RecordType::kView,
                    "FollowerClient::Share: a " << RecordTypeName(r.type) << " record");
      if (impl_->outbox.size() >= kMaxOutbox) {
        ++dropped;
        continue;
      }
      r.sequence = 0;
      r.written_ns = WallClockNs();
      std::string bytes = EncodeRecord(r);
      if (bytes.size() > kMaxViewOfferBytes) {
        ++too_large;
        continue;
      }
      impl_->outbox.push_back(std::move(bytes));
    }
  }
  if (dropped > 0)
    impl_->Log("fleet: " + std::to_string(dropped) + " views not offered: " +
               std::to_string(kMaxOutbox) + " are waiting for the connection already");
  if (too_large > 0)
    impl_->Log("fleet: " + std::to_string(too_large) + " views not offered: larger than " +
               std::to_string(kMaxViewOfferBytes) + " bytes");
}

bool FollowerClient::Verified() const {
  std::lock_guard<std::mutex> lock(impl_->stats_mutex);
  return impl_->verified;
}

std::string FollowerClient::Refusal() const {
  std::lock_guard<std::mutex> lock(impl_->stats_mutex);
  return impl_->refusal;
}

nlohmann::json ClientStatsJson(const ClientStats& stats) {
  std::vector<double> latency = stats.latency_ms;
  std::sort(latency.begin(), latency.end());
  const auto pct = [&](double p) {
    if (latency.empty()) return -1.0;
    return latency[static_cast<std::size_t>(p * static_cast<double>(latency.size() - 1) + 0.5)];
  };
  return {{"records_received", stats.received},
          {"records_applied", stats.applied},
          {"duplicates_dropped", stats.duplicates_dropped},
          {"ahead_dropped", stats.ahead_dropped},
          {"rejected", stats.rejected},
          {"subscriptions", stats.subscriptions},
          {"latency_samples", latency.size()},
          {"latency_median_ms", pct(0.5)},
          {"latency_p99_ms", pct(0.99)}};
}

ClientStats FollowerClient::stats() const {
  std::lock_guard<std::mutex> lock(impl_->stats_mutex);
  return impl_->stats;
}

}  // namespace mapless::fleet

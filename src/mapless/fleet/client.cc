#include "mapless/fleet/client.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <zmq.hpp>

#include "mapless/core/check.h"
#include "mapless/fleet/zmq_util.h"

namespace mapless::fleet {

namespace {

using Clock = std::chrono::steady_clock;

std::int64_t WallNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

constexpr std::size_t kMaxLatencySamples = 100000;

}  // namespace

struct FollowerClient::Impl {
  RouteCopy& copy;
  ClientOptions options;
  FleetLogger log_line;
  zmq::context_t context{1};
  zmq::socket_t dealer{context, zmq::socket_type::dealer};
  std::atomic<bool> stop{false};
  mutable std::mutex stats_mutex;
  ClientStats stats;
  Clock::time_point last_heard = Clock::now();
  Clock::time_point last_subscribe;
  std::int64_t first_subscribe_ns = 0;
  std::uint64_t rejected_sequence = ~0ull;
  bool unsent = false;  // the last subscription found no connection  // log a bad record once, not
                        // at every resend
  std::thread thread;

  Impl(RouteCopy& c, ClientOptions o, FleetLogger f)
      : copy(c), options(std::move(o)), log_line(std::move(f)) {}

  void Log(const std::string& line) {
    if (log_line) log_line(line);
  }

  // With ZMQ_IMMEDIATE a message is not queued while there is no connection: nothing was sent,
  // and the next round tries again.
  void Subscribe() {
    const std::string msg = EncodeSubscribe(copy.next_sequence());
    if (!dealer.send(zmq::buffer(msg), zmq::send_flags::dontwait)) {
      unsent = true;
      return;
    }
    unsent = false;
    last_subscribe = Clock::now();
    if (first_subscribe_ns == 0) first_subscribe_ns = WallNs();
    std::lock_guard<std::mutex> lock(stats_mutex);
    ++stats.subscriptions;
  }

  // Takes the waiting messages (up to a batch) and applies the run of records that continues the
  // copy; true when a gap was seen (ask again).
  bool Drain() {
    std::vector<Record> batch;
    bool gap = false;
    std::uint64_t next = copy.next_sequence();
    while (batch.size() < options.max_batch) {
      zmq::message_t msg;
      if (!dealer.recv(msg, zmq::recv_flags::dontwait)) {
        // Catching up, more records are on their way: wait a moment for them, so that many are
        // written with one flush (a live record, alone, is applied at once).
        if (batch.empty()) break;
        zmq::pollitem_t item{dealer.handle(), 0, ZMQ_POLLIN, 0};
        if (zmq::poll(&item, 1, std::chrono::milliseconds(2)) == 0) break;
        continue;
      }
      const std::int64_t now_ns = WallNs();
      last_heard = Clock::now();
      Record r;
      try {
        r = DecodeRecord(msg.to_string_view());
      } catch (const InputError& e) {
        std::lock_guard<std::mutex> lock(stats_mutex);
        ++stats.rejected;
        Log(std::string("fleet: rejected a message from the leader: ") + e.what());
        continue;
      }
      std::lock_guard<std::mutex> lock(stats_mutex);
      if (r.type == RecordType::kHeartbeat) {
        stats.leader_records = r.sequence;
        stats.leader_complete = r.parts[0] == "1";
        if (r.sequence > next) gap = true;  // the leader has more than this copy: ask
        continue;
      }
      ++stats.received;
      if (r.sequence < next) {
        ++stats.duplicates_dropped;
        continue;
      }
      if (r.sequence > next) {
        ++stats.ahead_dropped;
        gap = true;
        continue;
      }
      if (r.written_ns >= first_subscribe_ns && stats.latency_ms.size() < kMaxLatencySamples)
        stats.latency_ms.push_back(static_cast<double>(now_ns - r.written_ns) * 1e-6);
      batch.push_back(std::move(r));
      ++next;
    }
    if (!batch.empty()) {
      const std::uint64_t before = copy.next_sequence();
      try {
        copy.Apply(batch);
      } catch (const InputError& e) {
        const std::uint64_t bad = copy.next_sequence();
        if (bad != rejected_sequence)
          Log(std::string("fleet: rejected a record from the leader: ") + e.what());
        rejected_sequence = bad;
        std::lock_guard<std::mutex> lock(stats_mutex);
        ++stats.rejected;
      }
      std::lock_guard<std::mutex> lock(stats_mutex);
      stats.applied += copy.next_sequence() - before;
    }
    return gap;
  }

  void Run() {
    Subscribe();
    while (!stop) {
      zmq::pollitem_t item{dealer.handle(), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(unsent ? 20 : 100));
      if (stop) break;
      bool gap = false;
      if (item.revents & ZMQ_POLLIN) gap = Drain();
      const auto now = Clock::now();
      const double silent = std::chrono::duration<double>(now - last_heard).count();
      const double since_ask = std::chrono::duration<double>(now - last_subscribe).count();
      if (unsent || (gap && since_ask > 0.2) ||
          (silent > options.resubscribe_s && since_ask > options.resubscribe_s))
        Subscribe();
      std::lock_guard<std::mutex> lock(stats_mutex);
      stats.silent_s = silent;
    }
  }
};

FollowerClient::FollowerClient(RouteCopy& copy, ClientOptions options, FleetLogger log_line)
    : impl_(std::make_unique<Impl>(copy, std::move(options), std::move(log_line))) {
  Impl& c = *impl_;
  try {
    if (c.options.security.enabled()) {
      MAPLESS_CHECK(CurveAvailable(), "fleet: this libzmq was built without CURVE (libsodium)");
      c.dealer.set(zmq::sockopt::curve_serverkey, c.options.security.leader_public);
      c.dealer.set(zmq::sockopt::curve_publickey, c.options.security.key.public_key);
      c.dealer.set(zmq::sockopt::curve_secretkey, c.options.security.key.secret_key);
    }
    c.dealer.set(zmq::sockopt::maxmsgsize, static_cast<std::int64_t>(kMaxMessageBytes));
    c.dealer.set(zmq::sockopt::immediate, 1);
    c.dealer.set(zmq::sockopt::linger, 0);
    c.dealer.set(zmq::sockopt::reconnect_ivl, 200);
    c.dealer.set(zmq::sockopt::reconnect_ivl_max, 1000);
    SetHeartbeats(c.dealer);
    c.dealer.connect(c.options.connect);
  } catch (const zmq::error_t& e) {
    throw InputError("--connect " + c.options.connect + ": " + e.what());
  }
  c.thread = std::thread([&c] {
    try {
      c.Run();
    } catch (const std::exception& e) {
      c.Log(std::string("fleet: the link to the leader stopped: ") + e.what());
    }
  });
}

FollowerClient::~FollowerClient() {
  impl_->stop = true;
  if (impl_->thread.joinable()) impl_->thread.join();
}

ClientStats FollowerClient::stats() const {
  std::lock_guard<std::mutex> lock(impl_->stats_mutex);
  return impl_->stats;
}

}  // namespace mapless::fleet

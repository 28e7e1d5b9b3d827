#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <iterator>
#include <mutex>
#include <thread>
#include <zmq_addon.hpp>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"
#include "mapless/fleet/client.h"
#include "mapless/fleet/record.h"
#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"
#include "mapless/fleet/test_support.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"

namespace mapless::fleet {
namespace {

using namespace test;  // NOLINT(build/namespaces): the fixtures of fleet tests

TEST(FleetRecord, RoundTripsAndRejectsMalformedBytesWithOneLine) {
  Record r;
  r.type = RecordType::kKeyframe;
  r.sequence = 12;
  r.written_ns = 123456789;
  r.parts = {"yaml bytes", std::string("\0png\xff", 5)};
  const std::string bytes = EncodeRecord(r);
  const Record back = DecodeRecord(bytes);
  EXPECT_EQ(back, r);
  EXPECT_EQ(back.written_ns, r.written_ns);
  // Every truncation is refused, none crashes.
  for (std::size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(DecodeRecord(std::string_view(bytes).substr(0, n)), InputError) << n;
  std::string bad = bytes;
  bad[0] = 'X';
  EXPECT_THROW(DecodeRecord(bad), InputError);
  bad = bytes;
  bad[5] = 9;  // unknown type
  EXPECT_THROW(DecodeRecord(bad), InputError);
  bad = bytes + "x";  // trailing bytes
  EXPECT_THROW(DecodeRecord(bad), InputError);
  bad = bytes;
  bad[24] = 3;  // three parts for a keyframe
  EXPECT_THROW(DecodeRecord(bad), InputError);
  EXPECT_THROW(DecodeRecord(std::string(kMaxMessageBytes + 1, 'M')), InputError);
  EXPECT_EQ(DecodeSubscribe(EncodeSubscribe(41)), 41u);
  EXPECT_THROW(DecodeSubscribe(EncodeSubscribe(41) + "x"), InputError);
  EXPECT_THROW(DecodeSubscribe(EncodeSubscribe(kMaxSequence + 1)), InputError);
}

TEST(FleetRouteCopy, AFollowersCopyEqualsTheLeadersByteForByteAndResumes) {
  for (const bool funnel : {true, false}) {
    const std::vector<Record> records = funnel ? FunnelRecords(6, true) : ImageRecords(6, true);
    const std::string leader_dir = FreshDir(funnel ? "leader_f" : "leader_e");
    const std::string follower_dir = FreshDir(funnel ? "follower_f" : "follower_e");
    {
      RouteCopy leader(leader_dir);
      for (const Record& r : records) leader.Apply({r});  // one at a time, as taught
      EXPECT_TRUE(leader.complete());
    }
    {
      RouteCopy follower(follower_dir);
      follower.Apply({records.begin(), records.begin() + 4});
      EXPECT_EQ(follower.next_sequence(), 4u);
      EXPECT_FALSE(follower.complete());
    }
    // A restart: the copy goes on from record 4; a duplicate or a gap is refused unapplied.
    RouteCopy follower(follower_dir);
    ASSERT_EQ(follower.next_sequence(), 4u);
    EXPECT_THROW(follower.Apply({records[3]}), InputError);
    EXPECT_THROW(follower.Apply({records[5]}), InputError);
    EXPECT_EQ(follower.next_sequence(), 4u);
    follower.Apply({records.begin() + 4, records.end()});
    EXPECT_TRUE(follower.complete());
    EXPECT_EQ(Files(follower_dir), Files(leader_dir));
    // The records a reloaded copy serves are the ones it was given.
    const std::vector<Record> served = RouteCopy(leader_dir).RecordsFrom(0, 100);
    ASSERT_EQ(served.size(), records.size());
    for (std::size_t i = 0; i < served.size(); ++i) EXPECT_EQ(served[i], records[i]) << i;
    if (funnel) {
      ASSERT_NE(follower.FunnelRoute(), nullptr);
      EXPECT_EQ(follower.FunnelRoute()->keyframes.size(), 6u);
      EXPECT_TRUE(follower.FunnelRoute()->complete);
    } else {
      ASSERT_NE(follower.AppearanceRoute(), nullptr);
      EXPECT_EQ(follower.AppearanceRoute()->size(), 6);
      // The rebuilt eigenspace is the leader's, bit for bit.
      navigation::AppearanceLeader model;
      for (int i = 0; i < 6; ++i) {
        const auto image = MakeImage(i);
        model.AddStored(image.low, image.distance_m, image.odometry);
      }
      model.Finish();
      const auto expected = model.Snapshot();
      const auto got = follower.AppearanceRoute();
      EXPECT_EQ(got->space.mean, expected->space.mean);
      EXPECT_EQ(got->space.basis, expected->space.basis);
      EXPECT_EQ(got->space.projections, expected->space.projections);
    }
  }
}

TEST(FleetRouteCopy, ABadRecordChangesNothing) {
  const std::string dir = FreshDir("bad");
  std::vector<Record> records = FunnelRecords(3, false);
  RouteCopy copy(dir);
  copy.Apply({records[0], records[1]});
  const auto before = Files(dir);
  Record bad = records[2];
  bad.parts[0] = bad.parts[0].substr(0, bad.parts[0].size() / 2);  // truncated YAML
  EXPECT_THROW(copy.Apply({bad}), InputError);
  Record image = ImageRecords(1, false)[1];
  image.sequence = 2;  // an eigenspace image in a funnel route
  EXPECT_THROW(copy.Apply({image}), InputError);
  EXPECT_EQ(copy.next_sequence(), 2u);
  EXPECT_EQ(Files(dir), before);
  copy.Apply({records[2]});
  EXPECT_EQ(copy.next_sequence(), 3u);
}

// A catching-up batch is decoded on two threads (RouteCopy::Apply): the copy, and the refusal of a
// bad record in the middle of a batch, must be the same as when the records come one at a time.
TEST(FleetRouteCopy, ABatchAppliesAsTheSameRecordsOneAtATime) {
  std::vector<Record> records = FunnelRecords(16, true);
  RouteCopy whole(FreshDir("batch_whole"));
  whole.Apply(records);
  RouteCopy single(FreshDir("batch_single"));
  for (const Record& r : records) single.Apply({r});
  EXPECT_EQ(Files(whole.dir()), Files(single.dir()));
  ASSERT_NE(whole.FunnelRoute(), nullptr);
  EXPECT_EQ(whole.FunnelRoute()->keyframes.size(), 16u);

  // Record 9 (keyframe 8) goes back in time, record 12 is truncated: in a batch, and alone.
  route::Keyframe back = MakeKeyframe(8);
  back.t_ns = 1;  // before keyframe 7's
  records[9].parts = KeyframeRecord(back).parts;
  records[12].parts[0].resize(records[12].parts[0].size() / 2);
  std::string batch_error, single_error;
  RouteCopy batch(FreshDir("batch_bad"));
  try {
    batch.Apply(records);
  } catch (const InputError& e) {
    batch_error = e.what();
  }
  RouteCopy one(FreshDir("batch_bad_single"));
  for (const Record& r : records) {
    try {
      one.Apply({r});
    } catch (const InputError& e) {
      single_error = e.what();
      break;
    }
  }
  EXPECT_NE(batch_error.find("time goes backwards"), std::string::npos) << batch_error;
  EXPECT_EQ(batch_error, single_error);
  EXPECT_EQ(batch.next_sequence(), 9u);
  EXPECT_EQ(Files(batch.dir()), Files(one.dir()));
}

// Waits (bounded) until `done` holds.
// Issue 41: a leader's own records applied with what they were made from give the same route
// directory; each record is encoded once for the wire; a follower's method reads the route in
// pieces and gets the keyframes the whole-route snapshot has.
TEST(FleetRouteCopy, OwnRecordsEncodedOnceAndTheRouteReadInPieces) {
  RouteCopy applied(FreshDir("own_applied"));
  RouteCopy own(FreshDir("own_own"));
  route::Route pieces;
  int changes = 0;
  EXPECT_FALSE(own.UpdateFunnel(&pieces));  // nothing yet
  const std::vector<Record> records = FunnelRecords(6, true);
  for (std::size_t i = 0; i < records.size(); ++i) {
    applied.Apply({records[i]});
    std::optional<route::Keyframe> kf;
    if (records[i].type == RecordType::kKeyframe) kf = MakeKeyframe(static_cast<int>(i) - 1);
    own.ApplyOwn(records[i], kf);
    changes += own.UpdateFunnel(&pieces) ? 1 : 0;
    EXPECT_EQ(pieces.keyframes.size(), i == 0 ? 0u : std::min<std::size_t>(i, 6));
  }
  EXPECT_EQ(Files(applied.dir()), Files(own.dir()));
  EXPECT_EQ(changes, 7);  // six keyframes, then complete
  EXPECT_FALSE(own.UpdateFunnel(&pieces));
  ASSERT_NE(own.FunnelRoute(), nullptr);
  EXPECT_TRUE(pieces.complete);
  EXPECT_EQ(pieces.image_width, 320);
  ASSERT_EQ(pieces.keyframes.size(), own.FunnelRoute()->keyframes.size());
  for (std::size_t k = 0; k < pieces.keyframes.size(); ++k)
    EXPECT_EQ(pieces.keyframes[k].t_ns, own.FunnelRoute()->keyframes[k].t_ns);
  // The same bytes, the same buffer each time it is asked for.
  const std::shared_ptr<const std::string> e3 = own.Encoded(3);
  ASSERT_NE(e3, nullptr);
  EXPECT_EQ(*e3, EncodeRecord(own.RecordsFrom(3, 1).at(0)));
  EXPECT_EQ(own.Encoded(3).get(), e3.get());
  EXPECT_EQ(own.Encoded(records.size()), nullptr);
  // Route images: the image handed over is stored, not decoded again; the same files.
  RouteCopy images_applied(FreshDir("own_images_applied"));
  RouteCopy images_own(FreshDir("own_images_own"));
  const std::vector<Record> image_records = ImageRecords(4, true);
  for (std::size_t i = 0; i < image_records.size(); ++i) {
    images_applied.Apply({image_records[i]});
    const cv::Mat low = image_records[i].type == RecordType::kImage
                            ? MakeImage(static_cast<int>(i) - 1).low
                            : cv::Mat();
    images_own.ApplyOwn(image_records[i], std::nullopt, low);
  }
  EXPECT_EQ(Files(images_applied.dir()), Files(images_own.dir()));
}

TEST(FleetLink, AFollowerCatchesUpThenReceivesLiveRecordsOnLoopback) {
  const std::vector<Record> records = ImageRecords(30, true);
  RouteCopy leader(FreshDir("link_leader"));
  leader.Apply({records.begin(), records.begin() + 20});
  ServerOptions server_options;
  server_options.bind = "tcp://127.0.0.1:*";
  LeaderServer server(leader, server_options, nullptr);
  RouteCopy follower(FreshDir("link_follower"));
  ClientOptions client_options;
  client_options.connect = server.endpoint();
  FollowerClient client(follower, client_options, nullptr);
  ASSERT_TRUE(WaitFor([&] { return follower.next_sequence() == 20; }, 10.0));
  for (std::size_t i = 20; i < records.size(); ++i) {
    leader.Apply({records[i]});
    server.Notify();
  }
  ASSERT_TRUE(WaitFor([&] { return client.stats().applied == records.size(); }, 10.0));
  EXPECT_TRUE(follower.complete());
  EXPECT_EQ(Files(follower.dir()), Files(leader.dir()));
  const ClientStats stats = client.stats();
  EXPECT_EQ(stats.applied, records.size());
  EXPECT_EQ(stats.rejected, 0u);
  EXPECT_GE(stats.latency_ms.size(), 1u);  // the live ones
}

TEST(FleetLink, ACopyOfAnotherRouteIsRefusedNotContinued) {
  // The follower's directory holds the first records of one route; the leader serves another.
  const std::string stale = FreshDir("stale_copy");
  RouteCopy(stale).Apply(ImageRecords(4, false));
  std::vector<Record> other = ImageRecords(8, true);
  route::StoredAppearanceImage moved = MakeImage(3);
  moved.odometry.y_m += 1.0;
  other[4].parts[0] = route::AppearanceEntryJson(moved);  // record 4, the copy's last, differs
  RouteCopy leader(FreshDir("other_leader"));
  leader.Apply(other);
  ServerOptions server_options;
  server_options.bind = "tcp://127.0.0.1:*";
  LeaderServer server(leader, server_options, nullptr);
  const auto before = Files(stale);
  {
    RouteCopy copy(stale);
    ClientOptions options;
    options.connect = server.endpoint();
    FollowerClient client(copy, options, nullptr);
    ASSERT_TRUE(WaitFor([&] { return !client.Refusal().empty(); }, 10.0));
    EXPECT_FALSE(client.Verified());
    EXPECT_NE(client.Refusal().find("another route"), std::string::npos);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(copy.next_sequence(), 5u);  // the header and 4 images, nothing more
  }
  EXPECT_EQ(Files(stale), before);
  // A copy of the same route is confirmed and continued.
  const std::string same = FreshDir("same_copy");
  RouteCopy(same).Apply({other.begin(), other.begin() + 4});
  RouteCopy copy(same);
  ClientOptions options;
  options.connect = server.endpoint();
  FollowerClient client(copy, options, nullptr);
  ASSERT_TRUE(WaitFor([&] { return copy.complete(); }, 10.0));
  EXPECT_TRUE(client.Verified());
  EXPECT_TRUE(client.Refusal().empty());
  EXPECT_EQ(Files(same), Files(leader.dir()));
}

TEST(FleetLink, WithCurveAFollowerWithoutTheRightKeyReceivesNothing) {
  if (!CurveAvailable()) GTEST_SKIP() << "libzmq without CURVE";
  const std::string keys = FreshDir("keys");
  fs::create_directories(keys);
  const CurveKey leader_key = GenerateCurveKey(keys + "/leader.key");
  const CurveKey good = GenerateCurveKey(keys + "/good.key");
  const CurveKey stranger = GenerateCurveKey(keys + "/stranger.key");
  EXPECT_EQ(LoadCurveKey(keys + "/leader.key", true).secret_key, leader_key.secret_key);
  EXPECT_EQ(LoadCurveKey(keys + "/leader.key.pub", false).public_key, leader_key.public_key);
  EXPECT_THROW(LoadCurveKey(keys + "/leader.key.pub", true), InputError);
  EXPECT_EQ(fs::status(keys + "/leader.key").permissions() & fs::perms::others_read,
            fs::perms::none);

  const std::vector<Record> records = ImageRecords(5, true);
  RouteCopy leader(FreshDir("curve_leader"));
  leader.Apply(records);
  ServerOptions server_options;
  server_options.bind = "tcp://127.0.0.1:*";
  server_options.security.key = leader_key;
  server_options.security.allowed_public = {good.public_key};
  std::vector<std::string> lines;
  std::mutex lines_mutex;
  LeaderServer server(leader, server_options, [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(lines_mutex);
    lines.push_back(line);
  });
  const auto follow = [&](const CurveKey& key, const std::string& leader_public,
                          const std::string& name) {
    RouteCopy copy(FreshDir(name));
    ClientOptions options;
    options.connect = server.endpoint();
    options.security.key = key;
    options.security.leader_public = leader_public;
    FollowerClient client(copy, options, nullptr);
    WaitFor([&] { return copy.complete(); }, 2.0);
    return client.stats().received;
  };
  EXPECT_EQ(follow(good, leader_key.public_key, "curve_good"), records.size());
  EXPECT_EQ(follow(stranger, leader_key.public_key, "curve_stranger"), 0u);  // not admitted
  EXPECT_EQ(follow(good, stranger.public_key, "curve_wrong_leader"), 0u);    // wrong leader key
  EXPECT_GE(server.stats().refused, 2u);
  std::lock_guard<std::mutex> lock(lines_mutex);
  bool logged = false;
  for (const std::string& l : lines) logged |= l.find("refused") != std::string::npos;
  EXPECT_TRUE(logged);
}

}  // namespace
}  // namespace mapless::fleet

namespace mapless::fleet {
namespace {

// Issue 40: ZeroMQ takes a port of 99999 as another port; such endpoints are refused by name.
std::string FreshDirForEndpoints() {
  const std::string dir = ::testing::TempDir() + "mapless_fleet_endpoints";
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(dir + "_copy");
  return dir;
}

TEST(FleetLink, EndpointsOutsideThePortRangeAreRefused) {
  RouteCopy log(FreshDirForEndpoints());
  for (const std::string bad : {"tcp://127.0.0.1:99999", "tcp://127.0.0.1:", "tcp://:5600",
                                "udp://127.0.0.1:5600", "tcp://127.0.0.1:56x", "ipc://"}) {
    ServerOptions options;
    options.bind = bad;
    try {
      LeaderServer server(log, options, nullptr);
      ADD_FAILURE() << "bound " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--bind " + bad), std::string::npos) << e.what();
    }
  }
  RouteCopy copy(FreshDirForEndpoints() + "_copy");
  ClientOptions client;
  client.connect = "tcp://127.0.0.1:0";
  EXPECT_THROW(FollowerClient(copy, client, nullptr), InputError);
}

}  // namespace
}  // namespace mapless::fleet

namespace mapless::fleet {
namespace {

// Issue 40: 20,000 garbage messages from a fake leader gave 20,000 lines on the follower's stderr.
// They are rejected (counted) and said at most once a second.
TEST(FleetLink, AFollowerUnderGarbageSaysItOnceASecond) {
  zmq::context_t context(1);
  zmq::socket_t fake(context, zmq::socket_type::router);
  fake.set(zmq::sockopt::router_mandatory, 1);  // a full queue waits: every message arrives
  fake.bind("tcp://127.0.0.1:*");
  const std::string endpoint = fake.get(zmq::sockopt::last_endpoint);
  const std::string dir = ::testing::TempDir() + "mapless_fleet_garbage";
  std::filesystem::remove_all(dir);
  RouteCopy copy(dir);
  ClientOptions options;
  options.connect = endpoint;
  std::mutex mutex;
  int lines = 0;
  FollowerClient client(copy, options, [&](const std::string&) {
    std::lock_guard<std::mutex> lock(mutex);
    ++lines;
  });
  std::vector<zmq::message_t> hello;
  ASSERT_TRUE(zmq::recv_multipart(fake, std::back_inserter(hello)));  // its "from 0"
  const std::string id = hello[0].to_string();
  constexpr int kGarbage = 20000;
  for (int i = 0; i < kGarbage; ++i) {
    fake.send(zmq::buffer(id), zmq::send_flags::sndmore);
    fake.send(zmq::buffer("not a record " + std::to_string(i)), zmq::send_flags::none);
  }
  ASSERT_TRUE(WaitFor([&] { return client.stats().rejected >= kGarbage; }, 30.0))
      << client.stats().rejected;
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // the held-back count is said
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_GE(lines, 1);
  EXPECT_LE(lines, 40);  // one a second at most, and the line with the count
  EXPECT_EQ(copy.next_sequence(), 0u);
}

}  // namespace
}  // namespace mapless::fleet

namespace mapless::fleet {
namespace {

// Accepts every connection on 127.0.0.1:`port` and closes it at once: what a follower sees
// through a TCP proxy (a relay, a tunnel) while the leader behind it is down or restarting.
class AcceptAndClose {
 public:
  explicit AcceptAndClose(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int one = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
             ::listen(fd_, 16) == 0;
    thread_ = std::thread([this] {
      while (!stop_) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 20) <= 0) continue;
        const int c = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
        if (c < 0) continue;
        ::close(c);
        ++accepted_;
      }
    });
  }
  ~AcceptAndClose() {
    stop_ = true;
    thread_.join();
    ::close(fd_);
  }
  bool bound() const { return bound_; }
  int accepted() const { return accepted_; }

 private:
  int fd_ = -1;
  bool bound_ = false;
  std::atomic<bool> stop_{false};
  std::atomic<int> accepted_{0};
  std::thread thread_;
};

// CI, 2026-12-02 (fleet.eigenspace_faults): follower 3 reached the leader through a relay; the
// leader was killed and restarted, the relay took the follower's connections and closed them
// while nothing listened behind it, and the follower took three such closes for a CURVE mismatch
// and gave the leader up for good. A follower whose handshake with this leader has succeeded
// knows their keys agree: it keeps trying, saying so, and takes the rest of the route.
TEST(FleetLink, AFollowerBehindAProxyWaitsOutALeaderRestart) {
  const std::vector<Record> records = ImageRecords(30, true);
  RouteCopy leader(FreshDir("restart_leader"));
  leader.Apply({records.begin(), records.begin() + 10});
  ServerOptions server_options;
  server_options.bind = "tcp://127.0.0.1:*";
  auto server = std::make_unique<LeaderServer>(leader, server_options, nullptr);
  const std::string endpoint = server->endpoint();
  const int port = std::stoi(endpoint.substr(endpoint.rfind(':') + 1));
  RouteCopy follower(FreshDir("restart_follower"));
  ClientOptions client_options;
  client_options.connect = endpoint;
  std::mutex lines_mutex;
  std::vector<std::string> lines;
  FollowerClient client(follower, client_options, [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(lines_mutex);
    lines.push_back(line);
  });
  ASSERT_TRUE(WaitFor([&] { return follower.next_sequence() == 10; }, 10.0));
  server.reset();
  {
    AcceptAndClose proxy(port);
    ASSERT_TRUE(proxy.bound());
    ASSERT_TRUE(WaitFor([&] { return proxy.accepted() >= 5; }, 20.0)) << proxy.accepted();
  }
  EXPECT_EQ(client.Refusal(), "");
  leader.Apply({records.begin() + 10, records.end()});
  server_options.bind = endpoint;
  server = std::make_unique<LeaderServer>(leader, server_options, nullptr);
  ASSERT_TRUE(WaitFor([&] { return follower.complete(); }, 20.0)) << client.Refusal();
  EXPECT_EQ(Files(follower.dir()), Files(leader.dir()));
  std::lock_guard<std::mutex> lock(lines_mutex);
  bool said = false;
  for (const std::string& l : lines) said |= l.find("trying again") != std::string::npos;
  EXPECT_TRUE(said) << "the failed handshakes were not said";
}

}  // namespace
}  // namespace mapless::fleet

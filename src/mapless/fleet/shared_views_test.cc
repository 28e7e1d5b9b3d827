// Learned views in the route log (issue 45; shared_views.cc): a follower offers a view, the leader
// takes it as the next record, every copy applies it, and a restarted leader serves the same log.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mapless/core/check.h"
#include "mapless/fleet/client.h"
#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"
#include "mapless/fleet/test_support.h"
#include "mapless/route/route_store.h"

namespace mapless::fleet {
namespace {

using namespace test;  // NOLINT(build/namespaces): the fixtures of fleet tests

// A view of keyframe `index` as a repeat would learn it: other features, an offset.
route::KeyframeView LearnedView(int index, int salt, double offset_px) {
  const route::Keyframe other = MakeKeyframe(100 * (salt + 1) + index);
  route::KeyframeView view;
  view.keypoints = other.keypoints;
  view.descriptors = other.descriptors;
  view.offset_px = offset_px;
  return view;
}

// A complete funnel route of 5 keyframes in a leader's copy in `dir`.
std::vector<Record> LeaderRoute(RouteCopy* leader) {
  const std::vector<Record> records = FunnelRecords(5, true);
  leader->Apply(records);
  return records;
}

TEST(FleetSharedViews, ALeaderTakesAFollowersViewAndEveryCopyAppliesItByteForByte) {
  const std::string leader_dir = FreshDir("views_leader");
  const std::string follower_dir = FreshDir("views_follower");
  std::vector<Record> served;
  {
    RouteCopy leader(leader_dir);
    LeaderRoute(&leader);
    const std::uint64_t end = leader.next_sequence();
    const std::string line =
        leader.TakeView(ShareViewRecord(MakeKeyframe(2), LearnedView(2, 0, 12.5)), 5);
    EXPECT_NE(line.find("keyframe 2"), std::string::npos) << line;
    leader.TakeView(ShareViewRecord(MakeKeyframe(4), LearnedView(4, 0, -3.25)), 5);
    leader.TakeView(ShareViewRecord(MakeKeyframe(2), LearnedView(2, 1, 7.0)), 5);
    ASSERT_EQ(leader.next_sequence(), end + 3);
    served = leader.RecordsFrom(0, 100);
    EXPECT_EQ(served[end].type, RecordType::kView);
    // The route on disk: version 2, the views with the visits that took them.
    const route::Route stored = route::LoadRoute(leader_dir);
    EXPECT_EQ(stored.visits, 3);
    ASSERT_EQ(stored.keyframes[2].views.size(), 2u);
    EXPECT_EQ(stored.keyframes[2].views[0].offset_px, 12.5);
    EXPECT_EQ(stored.keyframes[2].views[0].learned_at, 1);
    EXPECT_EQ(stored.keyframes[2].views[1].learned_at, 3);
    EXPECT_EQ(stored.keyframes[4].views[0].offset_px, -3.25);
    EXPECT_EQ(stored.keyframes[4].views[0].descriptors.at<std::uint8_t>(0, 0),
              LearnedView(4, 0, 0).descriptors.at<std::uint8_t>(0, 0));
    // What a follower's method sees, also through the cached route.
    route::Route pieces;
    EXPECT_TRUE(leader.UpdateFunnel(&pieces));
    EXPECT_EQ(pieces.keyframes[2].views.size(), 2u);
    EXPECT_EQ(leader.FunnelRoute()->keyframes[4].views.size(), 1u);
  }
  {
    RouteCopy follower(follower_dir);
    follower.Apply({served.begin(), served.begin() + 8});  // the route and the first view
    route::Route pieces;
    follower.UpdateFunnel(&pieces);
    EXPECT_EQ(pieces.keyframes[2].views.size(), 1u);
    follower.Apply({served.begin() + 8, served.end()});
    EXPECT_TRUE(follower.UpdateFunnel(&pieces));  // the views shared since, on known keyframes
    EXPECT_EQ(pieces.keyframes[2].views.size(), 2u);
    EXPECT_EQ(pieces.keyframes[4].views.size(), 1u);
    EXPECT_FALSE(follower.UpdateFunnel(&pieces));
  }
  EXPECT_EQ(Files(follower_dir), Files(leader_dir));
  // A restarted leader (and a resumed follower) serves the same log, record for record.
  for (const std::string& dir : {leader_dir, follower_dir}) {
    const std::vector<Record> again = RouteCopy(dir).RecordsFrom(0, 100);
    ASSERT_EQ(again.size(), served.size()) << dir;
    for (std::size_t i = 0; i < served.size(); ++i)
      EXPECT_EQ(again[i], served[i]) << dir << " " << i;
  }
  // And takes the next view at the next visit.
  RouteCopy leader(leader_dir);
  leader.TakeView(ShareViewRecord(MakeKeyframe(0), LearnedView(0, 0, 1.0)), 5);
  EXPECT_EQ(route::LoadRoute(leader_dir).keyframes[0].views.at(0).learned_at, 4);
}

TEST(FleetSharedViews, AViewThatDoesNotFitTheRouteIsRefusedWithOneLineAndChangesNothing) {
  RouteCopy incomplete(FreshDir("views_incomplete"));
  incomplete.Apply(FunnelRecords(3, false));
  EXPECT_THROW(incomplete.TakeView(ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 0)), 5),
               InputError);
  RouteCopy leader(FreshDir("views_refused"));
  LeaderRoute(&leader);
  const auto files = Files(leader.dir());
  const std::uint64_t size = leader.next_sequence();
  const auto refused = [&](Record r, int max_views, const std::string& needle) {
    try {
      leader.TakeView(r, max_views);
      ADD_FAILURE() << "taken: " << needle;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  Record beyond = ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 0));
  beyond.parts[0] = R"({"keyframe": 5, "offset_px": 0})";
  refused(beyond, 5, "keyframe = 5");
  Record wild = ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 0));
  wild.parts[0] = R"({"keyframe": 1, "offset_px": 1e300})";
  refused(wild, 5, "offset_px");
  Record other_keyframe = ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 0));
  other_keyframe.parts[0] = R"({"keyframe": 3, "offset_px": 0})";
  refused(other_keyframe, 5, "a view of keyframe 1");
  route::KeyframeView floats = LearnedView(1, 0, 0);
  floats.descriptors.convertTo(floats.descriptors, CV_32F);
  refused(ShareViewRecord(MakeKeyframe(1), floats), 5, "descriptors");
  Record garbage = ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 0));
  garbage.parts[1] = "%YAML:1.0\nnot a keyframe";
  refused(garbage, 5, "keyframe 1");
  refused(ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 0)), 1, "its 1 views");
  EXPECT_EQ(leader.next_sequence(), size);
  EXPECT_EQ(Files(leader.dir()), files);
  // The same view twice; a place that is full.
  leader.TakeView(ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 2.0)), 3);
  refused(ShareViewRecord(MakeKeyframe(1), LearnedView(1, 0, 2.0)), 3, "has it already");
  leader.TakeView(ShareViewRecord(MakeKeyframe(1), LearnedView(1, 1, 2.0)), 3);
  refused(ShareViewRecord(MakeKeyframe(1), LearnedView(1, 2, 2.0)), 3, "its 3 views");
  EXPECT_EQ(leader.next_sequence(), size + 2);
  // A follower refuses a log whose views go back in time.
  std::vector<Record> log = leader.RecordsFrom(0, 100);
  std::swap(log[size].parts, log[size + 1].parts);
  RouteCopy follower(FreshDir("views_backwards"));
  EXPECT_THROW(follower.Apply(log), InputError);
  EXPECT_EQ(follower.next_sequence(), size + 1);
}

TEST(FleetSharedViews, AFollowerOffersAViewOverTheLinkAndItComesBackToEveryCopy) {
  RouteCopy leader(FreshDir("views_link_leader"));
  LeaderRoute(&leader);
  ServerOptions options;
  options.bind = "tcp://127.0.0.1:*";
  options.take_view = [&leader](const Record& r) { return leader.TakeView(r, 5); };
  LeaderServer server(leader, options, nullptr);
  ClientOptions client_options;
  client_options.connect = server.endpoint();
  RouteCopy a(FreshDir("views_link_a"));
  RouteCopy b(FreshDir("views_link_b"));
  FollowerClient client_a(a, client_options, nullptr);
  FollowerClient client_b(b, client_options, nullptr);
  const std::uint64_t end = leader.next_sequence();
  ASSERT_TRUE(WaitFor([&] { return a.complete() && b.complete(); }, 10.0));
  client_a.Share({ShareViewRecord(MakeKeyframe(3), LearnedView(3, 0, 4.5))});
  Record not_a_view = EndRecord();
  EXPECT_THROW(client_a.Share({not_a_view}), InputError);
  ASSERT_TRUE(
      WaitFor([&] { return a.next_sequence() == end + 1 && b.next_sequence() == end + 1; }, 10.0));
  EXPECT_EQ(server.stats().views_taken, 1u);
  EXPECT_EQ(client_a.stats().views_offered, 1u);
  EXPECT_EQ(Files(b.dir()), Files(leader.dir()));
  EXPECT_EQ(b.FunnelRoute()->keyframes[3].views.at(0).offset_px, 4.5);
}

TEST(FleetSharedViews, ALeaderThatTakesNoViewsRefusesThemAndSaysSo) {
  RouteCopy leader(FreshDir("views_none_leader"));
  LeaderRoute(&leader);
  ServerOptions options;
  options.bind = "tcp://127.0.0.1:*";
  std::vector<std::string> lines;
  std::mutex mutex;
  LeaderServer server(leader, options, [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(mutex);
    lines.push_back(line);
  });
  ClientOptions client_options;
  client_options.connect = server.endpoint();
  RouteCopy follower(FreshDir("views_none_follower"));
  FollowerClient client(follower, client_options, nullptr);
  ASSERT_TRUE(WaitFor([&] { return follower.complete(); }, 10.0));
  const std::uint64_t size = leader.next_sequence();
  client.Share({ShareViewRecord(MakeKeyframe(3), LearnedView(3, 0, 4.5))});
  ASSERT_TRUE(WaitFor([&] { return server.stats().views_refused == 1; }, 10.0));
  EXPECT_EQ(leader.next_sequence(), size);
  ASSERT_TRUE(WaitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        // The reason itself: the "follower joined" line of the same second does not hold it back.
        for (const std::string& l : lines)
          if (l.find("takes no views") != std::string::npos) return true;
        return false;
      },
      5.0));
}

}  // namespace
}  // namespace mapless::fleet

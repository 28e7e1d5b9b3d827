#include "mapless/live/protocol.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "mapless/core/check.h"
#include "mapless/live/server.h"

namespace mapless::live {
namespace {

TEST(LiveProtocol, ChoosesTheSubprotocolTheClientOffered) {
  EXPECT_EQ(ChooseSubprotocol({"foxglove.sdk.v1"}), "foxglove.sdk.v1");
  EXPECT_EQ(ChooseSubprotocol({"foxglove.websocket.v1"}), "foxglove.websocket.v1");
  EXPECT_EQ(ChooseSubprotocol({"x", "foxglove.websocket.v1", "foxglove.sdk.v1"}),
            "foxglove.websocket.v1");
  EXPECT_EQ(ChooseSubprotocol({"chat"}), "");
  EXPECT_EQ(ChooseSubprotocol({}), "");
}

TEST(LiveProtocol, TheServerIsReadOnly) {
  const auto info = nlohmann::json::parse(ServerInfoJson("mapless", "1"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["capabilities"], nlohmann::json::array({"time"}));
  EXPECT_FALSE(info.contains("supportedEncodings"));
}

TEST(LiveProtocol, MessageDataIsOpcodeSubscriptionTimeAndPayloadLittleEndian) {
  const std::string f = MessageDataFrame(0x01020304u, 0x1122334455667788ull, "ab");
  ASSERT_EQ(f.size(), 15u);
  EXPECT_EQ(f[0], '\x01');
  EXPECT_EQ(f.substr(1, 4), std::string("\x04\x03\x02\x01", 4));
  EXPECT_EQ(f.substr(5, 8), std::string("\x88\x77\x66\x55\x44\x33\x22\x11", 8));
  EXPECT_EQ(f.substr(13), "ab");
  const std::string t = TimeFrame(5);
  ASSERT_EQ(t.size(), 9u);
  EXPECT_EQ(t[0], '\x02');
  EXPECT_EQ(t[1], '\x05');
}

TEST(LiveProtocol, ParsesSubscribeAndUnsubscribe) {
  const ClientRequest s = ParseClientMessage(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":7,"channelId":1}]})");
  ASSERT_EQ(s.kind, ClientRequest::Kind::kSubscribe);
  ASSERT_EQ(s.subscriptions.size(), 2u);
  EXPECT_EQ(s.subscriptions[1], std::make_pair(7u, 1u));
  const ClientRequest u = ParseClientMessage(R"({"op":"unsubscribe","subscriptionIds":[7]})");
  ASSERT_EQ(u.kind, ClientRequest::Kind::kUnsubscribe);
  EXPECT_EQ(u.subscription_ids, std::vector<std::uint32_t>{7});
}

TEST(LiveProtocol, AnythingElseIsInvalidOrUnsupportedNeverAnException) {
  const char* const invalid[] = {
      "",
      "{",
      "[]",
      "42",
      R"({"op":7})",
      R"({"nop":"subscribe"})",
      R"({"op":"explode"})",
      R"({"op":"subscribe"})",
      R"({"op":"subscribe","subscriptions":{}})",
      R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})",
      R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":1}]})",
      R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})",
      R"({"op":"subscribe","subscriptions":[{"id":1}]})",
      R"({"op":"unsubscribe","subscriptionIds":["1"]})"};
  for (const char* text : invalid) {
    SCOPED_TRACE(text);
    const ClientRequest r = ParseClientMessage(text);
    EXPECT_EQ(r.kind, ClientRequest::Kind::kInvalid);
    EXPECT_FALSE(r.error.empty());
  }
  for (const char* op : {"advertise", "setParameters", "fetchAsset", "subscribeConnectionGraph"}) {
    const ClientRequest r = ParseClientMessage(std::string(R"({"op":")") + op + "\"}");
    EXPECT_EQ(r.kind, ClientRequest::Kind::kUnsupported) << op;
  }
  ParseLimits small;
  small.max_bytes = 10;
  EXPECT_EQ(ParseClientMessage(R"({"op":"subscribe","subscriptions":[]})", small).kind,
            ClientRequest::Kind::kInvalid);
  small = {};
  small.max_entries = 1;
  EXPECT_EQ(ParseClientMessage(R"({"op":"unsubscribe","subscriptionIds":[1,2]})", small).kind,
            ClientRequest::Kind::kInvalid);
}

TEST(LiveProtocol, SubscriptionsAreCheckedAndBounded) {
  Subscriptions subs(2);
  const std::vector<std::uint32_t> channels = {1, 2, 3};
  EXPECT_TRUE(subs.Apply(ParseClientMessage(
                             R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":1}]})"),
                         channels)
                  .empty());
  EXPECT_EQ(subs.For(1), std::vector<std::uint32_t>{10});
  // An unknown channel, a reused id, a channel subscribed twice, one too many: each refused.
  const auto refused =
      subs.Apply(ParseClientMessage(R"({"op":"subscribe","subscriptions":[{"id":11,"channelId":9},
        {"id":10,"channelId":2},{"id":12,"channelId":1},{"id":13,"channelId":2},
        {"id":14,"channelId":3}]})"),
                 channels);
  EXPECT_EQ(refused.size(), 4u);
  EXPECT_EQ(subs.size(), 2u);
  EXPECT_TRUE(
      subs.Apply(ParseClientMessage(R"({"op":"unsubscribe","subscriptionIds":[10]})"), channels)
          .empty());
  EXPECT_TRUE(subs.For(1).empty());
  EXPECT_EQ(
      subs.Apply(ParseClientMessage(R"({"op":"unsubscribe","subscriptionIds":[10]})"), channels)
          .size(),
      1u);
}

TEST(LiveAddress, ParsesPortAndAddressAndRefusesTheRest) {
  EXPECT_EQ(ParseAddress("8765").host, "127.0.0.1");
  EXPECT_EQ(ParseAddress("8765").port, 8765);
  EXPECT_EQ(ParseAddress("0.0.0.0:9000").host, "0.0.0.0");
  EXPECT_EQ(ParseAddress("[::1]:9000").host, "::1");
  EXPECT_EQ(ParseAddress("localhost:1").host, "127.0.0.1");
  for (const char* bad : {"", "x", "70000", "1.2.3:80", "host:80", ":80", "[::1]80", "80a"}) {
    EXPECT_THROW(ParseAddress(bad), InputError) << bad;
  }
}

}  // namespace
}  // namespace mapless::live

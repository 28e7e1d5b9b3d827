// The Foxglove WebSocket protocol, server side, as pure functions (no sockets here: server.h does
// the networking): the subprotocol a client may speak, the messages the server sends (server info,
// advertise, status, binary message data and time) and the parsing of what a client sends, with
// bounded sizes. The protocol: ../shared/specs/foxglove-websocket/spec.md (v1); current Foxglove
// and foxglove_bridge 3.2+ call the same messages `foxglove.sdk.v1`.
//
// mapless's live view is read-only: it advertises no capability but `time`, so a client can
// neither publish, nor call services, nor set parameters. Such requests are answered with a
// status message and otherwise ignored.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mapless::live {

inline constexpr const char* kSubprotocolSdk = "foxglove.sdk.v1";
inline constexpr const char* kSubprotocolV1 = "foxglove.websocket.v1";

// The subprotocol the server answers with: the first of the client's offers that it speaks
// (either name); empty when it speaks none of them (the connection is refused).
std::string ChooseSubprotocol(const std::vector<std::string>& offered);

struct Channel {
  std::uint32_t id = 0;
  std::string topic;
  std::string encoding;         // "json" or "cdr"
  std::string schema_name;      // "sensor_msgs/msg/CompressedImage", "foxglove.FrameTransform"
  std::string schema;           // the JSON Schema or the ROS 2 .msg text
  std::string schema_encoding;  // "jsonschema" or "ros2msg"
};

std::string ServerInfoJson(const std::string& name, const std::string& session_id);
std::string AdvertiseJson(const std::vector<Channel>& channels);
// level: 0 info, 1 warning, 2 error.
std::string StatusJson(int level, const std::string& message);

// Binary frames: opcode 0x01 (message data) and 0x02 (time), little-endian.
std::string MessageDataFrame(std::uint32_t subscription_id, std::uint64_t t_ns,
                             std::string_view payload);
std::string TimeFrame(std::uint64_t t_ns);

// What a client asked for in one text message.
struct ClientRequest {
  enum class Kind {
    kSubscribe,    // subscriptions: (subscription id, channel id) pairs
    kUnsubscribe,  // subscription_ids
    kUnsupported,  // a known operation the server does not offer (publishing, services,
                   // parameters, ...): op names it
    kInvalid,      // not a message of the protocol: error says why
  };
  Kind kind = Kind::kInvalid;
  std::string op;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> subscriptions;
  std::vector<std::uint32_t> subscription_ids;
  std::string error;
};

struct ParseLimits {
  std::size_t max_bytes = 64 * 1024;  // a longer text message is invalid
  std::size_t max_entries = 1024;     // subscriptions or ids in one message
};

// Never throws: anything that is not a subscribe or unsubscribe message of the protocol comes back
// as kUnsupported or kInvalid, with a short reason.
ClientRequest ParseClientMessage(std::string_view text, const ParseLimits& limits = {});

// One client's subscriptions, bounded: subscription id -> channel id.
class Subscriptions {
 public:
  explicit Subscriptions(std::size_t max_subscriptions = 256) : max_(max_subscriptions) {}
  // Applies a subscribe or unsubscribe request for channels among `known_channel_ids`; returns
  // what was refused (an unknown channel, a reused id, too many), empty when all was applied.
  std::vector<std::string> Apply(const ClientRequest& request,
                                 const std::vector<std::uint32_t>& known_channel_ids);
  // The subscription ids of `channel_id` (a client may subscribe a channel once: at most one).
  std::vector<std::uint32_t> For(std::uint32_t channel_id) const;
  std::size_t size() const { return entries_.size(); }

 private:
  std::size_t max_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> entries_;  // (subscription, channel)
};

}  // namespace mapless::live

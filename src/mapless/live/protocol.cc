#include "mapless/live/protocol.h"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace mapless::live {
namespace {

void PutLe(std::string* out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

// A subscription or channel id: a whole number in [0, 2^32).
bool ReadId(const nlohmann::json& j, std::uint32_t* id) {
  if (!j.is_number_integer() && !j.is_number_unsigned()) return false;
  if (j.is_number_unsigned()) {
    const auto v = j.get<std::uint64_t>();
    if (v > 0xffffffffull) return false;
    *id = static_cast<std::uint32_t>(v);
    return true;
  }
  const auto v = j.get<std::int64_t>();
  if (v < 0 || v > 0xffffffffll) return false;
  *id = static_cast<std::uint32_t>(v);
  return true;
}

ClientRequest Invalid(std::string error, std::string op = {}) {
  ClientRequest r;
  r.kind = ClientRequest::Kind::kInvalid;
  r.error = std::move(error);
  r.op = std::move(op);
  return r;
}

bool IsUnsupportedOp(const std::string& op) {
  static const char* const kOps[] = {"advertise",
                                     "unadvertise",
                                     "getParameters",
                                     "setParameters",
                                     "subscribeParameterUpdates",
                                     "unsubscribeParameterUpdates",
                                     "subscribeConnectionGraph",
                                     "unsubscribeConnectionGraph",
                                     "fetchAsset"};
  return std::find(std::begin(kOps), std::end(kOps), op) != std::end(kOps);
}

ClientRequest ParseSubscribe(const nlohmann::json& j, const ParseLimits& limits) {
  const auto it = j.find("subscriptions");
  if (it == j.end() || !it->is_array())
    return Invalid("subscribe: no subscriptions array", "subscribe");
  if (it->size() > limits.max_entries)
    return Invalid("subscribe: too many subscriptions", "subscribe");
  ClientRequest r;
  r.kind = ClientRequest::Kind::kSubscribe;
  r.op = "subscribe";
  for (const nlohmann::json& s : *it) {
    std::uint32_t id = 0, channel = 0;
    if (!s.is_object() || !s.contains("id") || !s.contains("channelId") || !ReadId(s["id"], &id) ||
        !ReadId(s["channelId"], &channel))
      return Invalid("subscribe: a subscription without a whole id and channelId", "subscribe");
    r.subscriptions.emplace_back(id, channel);
  }
  return r;
}

ClientRequest ParseUnsubscribe(const nlohmann::json& j, const ParseLimits& limits) {
  const auto it = j.find("subscriptionIds");
  if (it == j.end() || !it->is_array())
    return Invalid("unsubscribe: no subscriptionIds array", "unsubscribe");
  if (it->size() > limits.max_entries) return Invalid("unsubscribe: too many ids", "unsubscribe");
  ClientRequest r;
  r.kind = ClientRequest::Kind::kUnsubscribe;
  r.op = "unsubscribe";
  for (const nlohmann::json& s : *it) {
    std::uint32_t id = 0;
    if (!ReadId(s, &id))
      return Invalid("unsubscribe: an id that is not a whole number", "unsubscribe");
    r.subscription_ids.push_back(id);
  }
  return r;
}

}  // namespace

std::string ChooseSubprotocol(const std::vector<std::string>& offered) {
  for (const std::string& p : offered)
    if (p == kSubprotocolSdk || p == kSubprotocolV1) return p;
  return {};
}

std::string ServerInfoJson(const std::string& name, const std::string& session_id) {
  nlohmann::json j;
  j["op"] = "serverInfo";
  j["name"] = name;
  j["capabilities"] = nlohmann::json::array({"time"});  // read-only: no clientPublish, services
  j["metadata"] = nlohmann::json::object();
  j["sessionId"] = session_id;
  return j.dump();
}

std::string AdvertiseJson(const std::vector<Channel>& channels) {
  nlohmann::json j;
  j["op"] = "advertise";
  j["channels"] = nlohmann::json::array();
  for (const Channel& c : channels) {
    j["channels"].push_back({{"id", c.id},
                             {"topic", c.topic},
                             {"encoding", c.encoding},
                             {"schemaName", c.schema_name},
                             {"schema", c.schema},
                             {"schemaEncoding", c.schema_encoding}});
  }
  return j.dump();
}

std::string StatusJson(int level, const std::string& message) {
  nlohmann::json j{{"op", "status"}, {"level", level}, {"message", message}};
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string MessageDataFrame(std::uint32_t subscription_id, std::uint64_t t_ns,
                             std::string_view payload) {
  std::string out;
  out.reserve(13 + payload.size());
  out.push_back('\x01');
  PutLe(&out, subscription_id, 4);
  PutLe(&out, t_ns, 8);
  out.append(payload);
  return out;
}

std::string TimeFrame(std::uint64_t t_ns) {
  std::string out(1, '\x02');
  PutLe(&out, t_ns, 8);
  return out;
}

ClientRequest ParseClientMessage(std::string_view text, const ParseLimits& limits) {
  if (text.size() > limits.max_bytes) return Invalid("a text message over the size limit");
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return Invalid("not JSON");
  if (!j.is_object()) return Invalid("not a JSON object");
  const auto op_it = j.find("op");
  if (op_it == j.end() || !op_it->is_string()) return Invalid("no op");
  const std::string op = op_it->get<std::string>();
  if (op == "subscribe") return ParseSubscribe(j, limits);
  if (op == "unsubscribe") return ParseUnsubscribe(j, limits);
  ClientRequest r;
  r.op = op.size() > 64 ? op.substr(0, 64) : op;
  if (IsUnsupportedOp(op)) {
    r.kind = ClientRequest::Kind::kUnsupported;
    r.error = r.op + ": not offered (the live view is read-only)";
  } else {
    r.kind = ClientRequest::Kind::kInvalid;
    r.error = "unknown op";
  }
  return r;
}

std::vector<std::string> Subscriptions::Apply(const ClientRequest& request,
                                              const std::vector<std::uint32_t>& known_channel_ids) {
  std::vector<std::string> refused;
  if (request.kind == ClientRequest::Kind::kSubscribe) {
    for (const auto& entry : request.subscriptions) {
      const std::uint32_t id = entry.first,
                          channel = entry.second;  // (clang: lambdas capture these)
      const bool known = std::find(known_channel_ids.begin(), known_channel_ids.end(), channel) !=
                         known_channel_ids.end();
      const bool id_used = std::any_of(entries_.begin(), entries_.end(),
                                       [&](const auto& e) { return e.first == id; });
      const bool channel_taken = std::any_of(entries_.begin(), entries_.end(),
                                             [&](const auto& e) { return e.second == channel; });
      if (!known) {
        refused.push_back("subscribe: no channel " + std::to_string(channel));
      } else if (id_used) {
        refused.push_back("subscribe: subscription id " + std::to_string(id) + " is in use");
      } else if (channel_taken) {
        refused.push_back("subscribe: channel " + std::to_string(channel) + " is subscribed");
      } else if (entries_.size() >= max_) {
        refused.push_back("subscribe: too many subscriptions");
      } else {
        entries_.emplace_back(id, channel);
      }
    }
  } else if (request.kind == ClientRequest::Kind::kUnsubscribe) {
    for (const std::uint32_t id : request.subscription_ids) {
      const auto it = std::find_if(entries_.begin(), entries_.end(),
                                   [&](const auto& e) { return e.first == id; });
      if (it == entries_.end()) {
        refused.push_back("unsubscribe: no subscription " + std::to_string(id));
      } else {
        entries_.erase(it);
      }
    }
  }
  // Bounded answer: a flood of bad entries is summed up, not echoed.
  if (refused.size() > 4) {
    const std::size_t more = refused.size() - 3;
    refused.resize(3);
    refused.push_back("and " + std::to_string(more) + " more refused");
  }
  return refused;
}

std::vector<std::uint32_t> Subscriptions::For(std::uint32_t channel_id) const {
  std::vector<std::uint32_t> out;
  for (const auto& [id, channel] : entries_)
    if (channel == channel_id) out.push_back(id);
  return out;
}

}  // namespace mapless::live

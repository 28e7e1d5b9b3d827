// Small ZeroMQ helpers shared by the leader's and the follower's sides (internal to fleet/).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>
#include <zmq.hpp>

#include "mapless/core/check.h"

namespace mapless::fleet {

// Receives one whole multipart message; false when none is waiting (wait = false) or on EINTR.
inline bool RecvAll(zmq::socket_t& socket, std::vector<zmq::message_t>* parts, bool wait = true) {
  parts->clear();
  while (true) {
    zmq::message_t part;
    const auto got = socket.recv(
        part, wait || !parts->empty() ? zmq::recv_flags::none : zmq::recv_flags::dontwait);
    if (!got) return false;
    const bool more = part.more();
    parts->push_back(std::move(part));
    if (!more) return true;
  }
}

enum class SendResult { kSent, kFull, kGone };

// Sends `bytes` to the peer `id` of a ROUTER socket with ZMQ_ROUTER_MANDATORY, without waiting.
inline SendResult SendTo(zmq::socket_t& router, const std::string& id, std::string_view bytes) {
  try {
    if (!router.send(zmq::buffer(id), zmq::send_flags::sndmore | zmq::send_flags::dontwait))
      return SendResult::kFull;
    router.send(zmq::buffer(bytes.data(), bytes.size()), zmq::send_flags::dontwait);
    return SendResult::kSent;
  } catch (const zmq::error_t& e) {
    if (e.num() == EHOSTUNREACH) return SendResult::kGone;
    throw;
  }
}

// The same for bytes shared with other sends (a record encoded once for every follower): ZeroMQ
// queues them without a copy, holding `bytes` until the message is gone.
inline SendResult SendTo(zmq::socket_t& router, const std::string& id,
                         const std::shared_ptr<const std::string>& bytes) {
  try {
    if (!router.send(zmq::buffer(id), zmq::send_flags::sndmore | zmq::send_flags::dontwait))
      return SendResult::kFull;
    auto* hold = new std::shared_ptr<const std::string>(bytes);
    zmq::message_t message(
        const_cast<char*>(bytes->data()), bytes->size(),
        [](void*, void* hint) { delete static_cast<std::shared_ptr<const std::string>*>(hint); },
        hold);
    router.send(message, zmq::send_flags::dontwait);
    return SendResult::kSent;
  } catch (const zmq::error_t& e) {
    if (e.num() == EHOSTUNREACH) return SendResult::kGone;
    throw;
  }
}

// Refuses an endpoint ZeroMQ would take wrongly or silently (a port of 99999 wraps to another
// port): tcp://HOST:PORT with PORT 1-65535 (or * when binding), or ipc://PATH. Throws InputError
// naming `option`.
inline void CheckEndpoint(const std::string& endpoint, const std::string& option, bool bind) {
  const auto fail = [&](const std::string& why) {
    throw InputError(option + " " + endpoint + ": " + why);
  };
  if (endpoint.rfind("ipc://", 0) == 0) {
    if (endpoint.size() == 6) fail("ipc:// needs a path");
    return;
  }
  if (endpoint.rfind("tcp://", 0) != 0) fail("expected tcp://HOST:PORT or ipc://PATH");
  const std::size_t colon = endpoint.rfind(':');
  if (colon < 6 || colon == 5) fail("expected tcp://HOST:PORT");
  const std::string host = endpoint.substr(6, colon - 6);
  const std::string port = endpoint.substr(colon + 1);
  if (host.empty()) fail("no host (tcp://127.0.0.1:PORT, or tcp://*:PORT to bind every interface)");
  if (port == "*" || port == "0") {
    if (!bind) fail("a follower needs the leader's port, not " + port);
    return;
  }
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos)
    fail("port '" + port + "' is not a number from 1 to 65535");
  const long value = std::stol(port);
  if (value < 1 || value > 65535) fail("port " + port + " is not from 1 to 65535");
}

// ZMTP heartbeats: a connection that stops answering is dropped within seconds and re-dialled by
// the follower, instead of waiting for TCP's own timeouts.
inline void SetHeartbeats(zmq::socket_t& socket) {
  socket.set(zmq::sockopt::heartbeat_ivl, 1000);
  socket.set(zmq::sockopt::heartbeat_timeout, 3000);
  socket.set(zmq::sockopt::heartbeat_ttl, 3000);
}

}  // namespace mapless::fleet

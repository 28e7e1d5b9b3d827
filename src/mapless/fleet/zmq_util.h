// Small ZeroMQ helpers shared by the leader's and the follower's sides (internal to fleet/).
#pragma once

#include <string>
#include <string_view>
#include <vector>
#include <zmq.hpp>

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

// ZMTP heartbeats: a connection that stops answering is dropped within seconds and re-dialled by
// the follower, instead of waiting for TCP's own timeouts.
inline void SetHeartbeats(zmq::socket_t& socket) {
  socket.set(zmq::sockopt::heartbeat_ivl, 1000);
  socket.set(zmq::sockopt::heartbeat_timeout, 3000);
  socket.set(zmq::sockopt::heartbeat_ttl, 3000);
}

}  // namespace mapless::fleet

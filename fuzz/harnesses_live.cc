// The live view's network parsers as the server runs them (issue 67): websocketpp's HTTP request
// parser (the handshake and `GET /`) and its WebSocket frame parser (RFC 6455, hybi13), with the
// server's limits, each complete message then going to the live view's own message parser. Built
// with websocketpp + standalone asio, as live/server.cc.
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/http/request.hpp>
#include <websocketpp/processors/hybi13.hpp>
// (websocketpp before the rest: it defines what asio needs standalone)

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "harnesses.h"
#include "mapless/live/protocol.h"
#include "mapless/live/server.h"

namespace mapless::fuzz {
namespace {

using Config = websocketpp::config::asio;
using Processor = websocketpp::processor::hybi13<Config>;

// The server's limit on a client's message (and an HTTP body).
constexpr std::size_t kMaxMessageBytes = 64 * 1024;  // live::ServerOptions::max_message_bytes

// The input as the bytes of up to 16 reads of one connection (split at "\xffNXT"), as they come
// off the socket: the parsers keep their state across reads.
std::vector<std::string> Reads(const std::string& input) {
  std::vector<std::string> reads;
  std::size_t start = 0;
  while (reads.size() < 16 && start <= input.size()) {
    const std::size_t end = std::min(input.find("\xffNXT", start), input.size());
    reads.push_back(input.substr(start, end - start));
    start = end + 4;
  }
  return reads;
}

}  // namespace

void LiveHttpRequest(const std::string& input) {
  websocketpp::http::parser::request request;
  request.set_max_body_size(kMaxMessageBytes);
  Config::rng_type rng;
  Processor processor(false, true, std::make_shared<Config::con_msg_manager_type>(), rng);
  for (const std::string& bytes : Reads(input)) {
    try {
      const std::size_t used = request.consume(bytes.data(), bytes.size());
      if (used > bytes.size()) std::abort();
    } catch (const websocketpp::http::exception&) {
      return;  // refused: the server answers 400 and closes
    }
    if (!request.ready()) continue;
    // What the server then looks at: the resource (the page or 404), the handshake, the
    // subprotocols offered and the one chosen.
    (void)request.get_uri();
    if (websocketpp::processor::is_websocket_handshake(request)) {
      (void)processor.validate_handshake(request);
      std::vector<std::string> offered;
      if (!processor.extract_subprotocols(request, offered)) {
        const std::string chosen = live::ChooseSubprotocol(offered);
        if (!chosen.empty() && chosen != live::kSubprotocolSdk && chosen != live::kSubprotocolV1)
          std::abort();  // only a subprotocol the live view speaks is ever chosen
      }
    }
    return;
  }
}

void LiveWebSocketFrames(const std::string& input) {
  Config::rng_type rng;
  Processor processor(false, true, std::make_shared<Config::con_msg_manager_type>(), rng);
  processor.set_max_message_size(kMaxMessageBytes);
  for (std::string bytes : Reads(input)) {
    std::size_t done = 0;
    while (done < bytes.size()) {
      std::error_code ec;
      const std::size_t used = processor.consume(
          reinterpret_cast<std::uint8_t*>(bytes.data()) + done, bytes.size() - done, ec);
      if (ec) return;  // a protocol error: the server closes the connection
      if (used > bytes.size() - done) std::abort();
      done += used;
      if (!processor.ready()) {
        if (used == 0) break;
        continue;
      }
      const Config::message_type::ptr message = processor.get_message();
      if (!message) std::abort();
      if (message->get_payload().size() > kMaxMessageBytes) std::abort();
      // A text message goes to the live view's parser, as the server hands it on.
      if (message->get_opcode() == websocketpp::frame::opcode::text) {
        const live::ClientRequest r = live::ParseClientMessage(message->get_payload());
        if ((r.kind == live::ClientRequest::Kind::kInvalid ||
             r.kind == live::ClientRequest::Kind::kUnsupported) &&
            r.error.empty())
          std::abort();
      }
    }
  }
}

}  // namespace mapless::fuzz

// The live view's server: the Foxglove WebSocket protocol (protocol.h) and the page
// (`http://ADDRESS:PORT/`) on one port, on websocketpp + standalone asio (Debian's
// libwebsocketpp-dev, libasio-dev; docs/architecture.md says why), in a thread of its own.
//
// The robot comes first. The loop hands a frame over with Offer(), which takes a lock for a
// pointer swap and never touches a socket: the server keeps only the newest frame not yet sent,
// and its thread makes the messages (feed.h: the JPEG encoding is done there) and sends them.
// Each client's queue is bounded: above max_buffered_bytes its images are dropped (the next frame
// brings newer ones), above twice that everything is, and a client whose queue stays full for
// stall_timeout_s is cut off. Read-only: no client publishing, no services, no parameters.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mapless/live/feed.h"
#include "mapless/live/protocol.h"

namespace mapless::live {

struct Address {
  std::string host = "127.0.0.1";
  int port = 8765;
};

// "[ADDRESS:]PORT" ("8765", "0.0.0.0:8765", "[::1]:8765", "localhost:8765"); the address defaults
// to 127.0.0.1 (loopback). Throws InputError naming the value. Port 0: any free port.
Address ParseAddress(const std::string& text);

struct ServerOptions {
  Address address;
  std::string name = "mapless";
  std::size_t max_clients = 8;
  std::size_t max_buffered_bytes = 2 << 20;   // per client: above it, images are dropped
  double stall_timeout_s = 5.0;               // queue over the limit this long: cut off
  std::size_t max_message_bytes = 64 * 1024;  // a larger frame from a client closes it (1009)
  int max_requests_per_s = 100;               // more text messages a second: cut off (a flood)
  double handshake_timeout_s = 5.0;           // half-open connections are closed after this
  // Connections open at once, handshakes under way included (each holds websocketpp's buffers,
  // about 40 KB, until its handshake times out): more are closed as they are accepted.
  std::size_t max_connections = 64;
  // Lines about clients (came, went, refused, cut off, sent bad input): at most this many a
  // second; the rest are counted and said in one line ("... 190 more lines about clients").
  int max_log_lines_per_s = 5;
  // One line per event worth telling (a client came or went, was refused or cut off, sent bad
  // input); called on the server's thread. Empty: silent.
  std::function<void(const std::string&)> log;
};

struct ServerStats {
  std::uint64_t frames_offered = 0;
  std::uint64_t frames_sent = 0;  // frames made into messages (the others were replaced)
  std::uint64_t messages_sent = 0;
  std::uint64_t images_dropped = 0;  // for slow clients
  std::uint64_t clients_cut_off = 0;
  std::uint64_t messages_dropped = 0;      // replies and latched messages for a full queue
  std::uint64_t connections_refused = 0;   // over max_connections
  std::uint64_t log_lines_suppressed = 0;  // over max_log_lines_per_s
};

class Server {
 public:
  // Binds and starts serving (InputError when the address cannot be bound). `page`: the HTML of
  // `GET /`; `feed` makes each frame's messages.
  Server(std::vector<Channel> channels, std::unique_ptr<Feed> feed, std::string page,
         ServerOptions options);
  ~Server();  // closes every connection and joins the thread
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  int port() const;  // the bound port (the one chosen for port 0)
  std::size_t clients() const;
  // From the loop's thread: the newest frame. Returns at once; nothing is done without a client.
  void Offer(FrameView frame);
  ServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mapless::live

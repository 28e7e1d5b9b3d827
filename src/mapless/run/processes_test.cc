// The evaluation's TCP relay (processes.h) on loopback.
#include "mapless/run/processes.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>

namespace mapless::run {
namespace {

sockaddr_in Loopback(int port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  return addr;
}

int ListenOn(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  const sockaddr_in addr = Loopback(port);
  EXPECT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
  EXPECT_EQ(::listen(fd, 8), 0);
  return fd;
}

int ConnectTo(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const sockaddr_in addr = Loopback(port);
  EXPECT_EQ(::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
  return fd;
}

// The connection the relay dialled for a client, accepted at the target (within 5 s).
int AcceptWithin(int listener) {
  pollfd p{listener, POLLIN, 0};
  if (::poll(&p, 1, 5000) != 1) return -1;
  return ::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
}

// Up to `size` bytes read from `fd` within 5 s.
std::string ReadWithin(int fd, std::size_t size) {
  std::string got;
  char buffer[256];
  pollfd p{fd, POLLIN, 0};
  while (got.size() < size && ::poll(&p, 1, 5000) == 1) {
    const ssize_t n = ::read(fd, buffer, std::min(sizeof(buffer), size - got.size()));
    if (n <= 0) break;
    got.append(buffer, static_cast<std::size_t>(n));
  }
  return got;
}

TEST(Relay, APeerThatStopsReadingHoldsUpNoOtherConnection) {
  const int target_port = FreePort();
  const int target = ListenOn(target_port);
  const int small = 4096;  // inherited by the accepted connections: A's server's window stays small
  ::setsockopt(target, SOL_SOCKET, SO_RCVBUF, &small, sizeof(small));
  const int relay_port = FreePort();
  {
    Relay relay(relay_port, target_port);
    // Connection A: its client floods, its server never reads (small buffers fill at once).
    const int a_client = ConnectTo(relay_port);
    const int a_server = AcceptWithin(target);
    ASSERT_GE(a_server, 0);
    ::fcntl(a_client, F_SETFL, ::fcntl(a_client, F_GETFL) | O_NONBLOCK);
    const std::string chunk(1 << 16, 'a');
    std::size_t sent = 0;
    // Until the client's own buffer stays full for 0.2 s (at most 32 MB).
    for (int idle = 0; idle < 20 && sent < (32u << 20);) {
      const ssize_t n = ::send(a_client, chunk.data(), chunk.size(), MSG_NOSIGNAL);
      if (n > 0) {
        sent += static_cast<std::size_t>(n);
        idle = 0;
      } else {
        ++idle;
        ::usleep(10000);
      }
    }
    EXPECT_GT(sent, chunk.size());  // more than the relay holds: it is stuck on A's server
    EXPECT_LT(sent, 32u << 20);     // and A's client was held up
    // Connection B still passes both ways.
    const int b_client = ConnectTo(relay_port);
    const int b_server = AcceptWithin(target);
    ASSERT_GE(b_server, 0);
    ASSERT_EQ(::send(b_client, "ping", 4, MSG_NOSIGNAL), 4);
    EXPECT_EQ(ReadWithin(b_server, 4), "ping");
    ASSERT_EQ(::send(b_server, "pong", 4, MSG_NOSIGNAL), 4);
    EXPECT_EQ(ReadWithin(b_client, 4), "pong");
    // A's server reads at last: what A's client sent arrives, in order, nothing lost.
    std::string all = ReadWithin(a_server, sent);
    EXPECT_EQ(all.size(), sent);
    EXPECT_EQ(all.find_first_not_of('a'), std::string::npos);
    for (int fd : {a_client, a_server, b_client, b_server}) ::close(fd);
  }  // the relay stops and its thread joins
  ::close(target);
}

TEST(Relay, DownClosesConnectionsAndRefusesNewOnesUntilUp) {
  const int target_port = FreePort();
  const int target = ListenOn(target_port);
  const int relay_port = FreePort();
  Relay relay(relay_port, target_port);
  const int client = ConnectTo(relay_port);
  const int server = AcceptWithin(target);
  ASSERT_GE(server, 0);
  relay.Down();
  EXPECT_EQ(ReadWithin(client, 1), "");  // closed by the relay
  ::usleep(100000);
  const int refused = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const sockaddr_in addr = Loopback(relay_port);
  EXPECT_NE(::connect(refused, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
  relay.Up();
  ::usleep(100000);
  const int again = ConnectTo(relay_port);
  const int again_server = AcceptWithin(target);
  EXPECT_GE(again_server, 0);
  for (int fd : {client, server, refused, again, again_server, target}) ::close(fd);
}

}  // namespace
}  // namespace mapless::run

#include "mapless/run/keyboard.h"

#include <poll.h>
#include <unistd.h>

#include <cerrno>

namespace mapless::run {

Keyboard::Keyboard(int fd) : fd_(fd) {
  terminal_ = ::isatty(fd_) == 1 && ::tcgetattr(fd_, &saved_) == 0;
  if (!terminal_) return;
  termios raw = saved_;
  raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO | ISIG | IEXTEN);
  raw.c_iflag &= ~static_cast<tcflag_t>(IXON | ICRNL);
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  ::tcsetattr(fd_, TCSANOW, &raw);
}

Keyboard::~Keyboard() {
  if (terminal_) ::tcsetattr(fd_, TCSANOW, &saved_);
}

robot::KeyInput Keyboard::Read() {
  robot::KeyInput input;
  // At most 4 KB a call: a person types a few keys a frame; a pipe pouring more waits its turn.
  while (!closed_ && input.bytes.size() < 4096) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, 0);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    if ((p.revents & POLLIN) == 0) {
      closed_ = (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0;
      break;
    }
    char buffer[256];
    const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) {
      closed_ = true;  // the end of a pipe or file; EIO: the terminal went away
      break;
    }
    input.bytes.append(buffer, static_cast<std::size_t>(n));
  }
  input.closed = closed_;
  return input;
}

}  // namespace mapless::run

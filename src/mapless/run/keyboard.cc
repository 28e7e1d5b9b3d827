#include "mapless/run/keyboard.h"

#include <poll.h>
#include <unistd.h>

#include <cerrno>

namespace mapless::run {
namespace {

constexpr char kCtrlC = 0x03;
constexpr char kCtrlD = 0x04;
constexpr std::size_t kMaxPendingBytes = 64 * 1024;

}  // namespace

Keyboard::Keyboard(int fd, std::function<void()> on_end) : fd_(fd), on_end_(std::move(on_end)) {
  terminal_ = ::isatty(fd_) == 1 && ::tcgetattr(fd_, &saved_) == 0;
  if (terminal_) {
    termios raw = saved_;
    raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO | ISIG | IEXTEN);
    raw.c_iflag &= ~static_cast<tcflag_t>(IXON | ICRNL);
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    ::tcsetattr(fd_, TCSANOW, &raw);
  }
  reader_ = std::thread([this] { ReadLoop(); });
}

Keyboard::~Keyboard() {
  stop_ = true;
  if (reader_.joinable()) reader_.join();
  if (terminal_) ::tcsetattr(fd_, TCSANOW, &saved_);
}

void Keyboard::ReadLoop() {
  bool closed = false;
  while (!stop_.load() && !closed) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, 10);  // the stop flag is seen within 10 ms
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) {
      if (ready < 0) closed = true;
      continue;
    }
    std::string got;
    if ((p.revents & POLLIN) != 0) {
      char buffer[256];
      const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) closed = true;  // the end of a pipe or file; EIO: the terminal went away
      if (n > 0) got.assign(buffer, static_cast<std::size_t>(n));
    } else {
      closed = (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0;
    }
    const bool end_key =
        got.find(kCtrlC) != std::string::npos || got.find(kCtrlD) != std::string::npos;
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (bytes_.size() + got.size() <= kMaxPendingBytes) bytes_ += got;
      closed_ = closed;
    }
    if ((end_key || closed) && !ended_.exchange(true) && on_end_) on_end_();
    if (end_key) break;  // nothing typed after the end counts
  }
}

robot::KeyInput Keyboard::Read() {
  robot::KeyInput input;
  std::lock_guard<std::mutex> lock(mu_);
  input.bytes.swap(bytes_);
  input.closed = closed_;
  return input;
}

}  // namespace mapless::run

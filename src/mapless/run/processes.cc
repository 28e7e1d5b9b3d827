#include "mapless/run/processes.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::run {

namespace fs = std::filesystem;

namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

int FreePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof(addr);
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
    if (fd >= 0) ::close(fd);
    throw InputError("eval fleet: cannot find a free port on 127.0.0.1");
  }
  ::close(fd);
  return ntohs(addr.sin_port);
}

void Child::Start() {
  pid_ = ::fork();
  MAPLESS_CHECK(pid_ >= 0, "eval fleet: cannot fork");
  if (pid_ == 0) {
    const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd >= 0) {
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
    }
    std::vector<char*> argv;
    for (std::string& a : args_) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(program_.c_str(), argv.data());
    ::_exit(127);
  }
  exited_ = false;
}

void Child::Signal(int signal) {
  if (pid_ > 0 && !exited_) ::kill(pid_, signal);
}

bool Child::Poll() {
  if (exited_ || pid_ <= 0) return exited_;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    exited_ = true;
    code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  return exited_;
}

void Child::Wait(double seconds) {
  const auto t0 = Clock::now();
  while (!Poll() && SecondsSince(t0) < seconds)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (!Poll()) {
    Signal(SIGKILL);
    while (!Poll()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

Relay::Relay(int listen_port, int target_port)
    : listen_port_(listen_port), target_port_(target_port) {
  Listen();
  thread_ = std::thread([this] { Run(); });
}

Relay::~Relay() {
  stop_ = true;
  thread_.join();
  CloseAll();
}

void Relay::Listen() {
  listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  const int one = 1;
  ::setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(listen_port_));
  if (::bind(listener_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::listen(listener_, 16) != 0)
    throw InputError("eval fleet: the relay cannot listen on port " + std::to_string(listen_port_));
}

int Relay::Dial() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<std::uint16_t>(target_port_));
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return -1;
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
  return fd;
}

void Relay::CloseAll() {
  for (const Pair& p : pairs_) {
    ::close(p.fd[0]);
    ::close(p.fd[1]);
  }
  pairs_.clear();
  if (listener_ >= 0) ::close(listener_);
  listener_ = -1;
}

// One side of a pair after poll: writes what the other side sent while this one can take it, and
// reads only when what it sent before has gone on. False: the pair is finished.
bool Relay::Forward(Pair& pair, int side, short revents) {
  const auto flush = [&](int from) {
    std::string& out = pair.pending[from];
    while (!out.empty()) {
      const ssize_t w = ::send(pair.fd[1 - from], out.data(), out.size(), MSG_NOSIGNAL);
      if (w < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
      out.erase(0, static_cast<std::size_t>(w));
    }
    return true;
  };
  // An error, or a hang-up with nothing left to read (a reset): nothing more can pass.
  if ((revents & POLLERR) || ((revents & POLLHUP) && !(revents & POLLIN))) return false;
  if ((revents & POLLOUT) && !flush(1 - side)) return false;
  if (!(revents & POLLIN) || !pair.pending[side].empty()) return true;
  char buffer[1 << 16];
  const ssize_t n = ::read(pair.fd[side], buffer, sizeof(buffer));
  if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
  if (n == 0) return false;  // closed: everything it sent has been passed on
  pair.pending[side].assign(buffer, static_cast<std::size_t>(n));
  return flush(side);
}

void Relay::Run() {
  while (!stop_) {
    if (down_) {
      if (listener_ >= 0 || !pairs_.empty()) CloseAll();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    if (listener_ < 0) Listen();
    std::vector<pollfd> fds = {{listener_, POLLIN, 0}};
    for (const Pair& p : pairs_) {
      for (int side = 0; side < 2; ++side) {
        const short in = p.pending[side].empty() ? POLLIN : 0;
        const short out = p.pending[1 - side].empty() ? 0 : POLLOUT;
        fds.push_back({p.fd[side], static_cast<short>(in | out), 0});
      }
    }
    ::poll(fds.data(), fds.size(), 20);
    const std::size_t polled = pairs_.size();  // a pair accepted below waits for the next poll
    if (fds[0].revents & POLLIN) {
      const int in = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
      if (in >= 0) {
        const int out = Dial();
        if (out < 0) {
          ::close(in);
        } else {
          pairs_.push_back(Pair{{in, out}, {}});
        }
      }
    }
    std::vector<std::size_t> dead;
    for (std::size_t i = 0; i < polled; ++i) {
      for (int side = 0; side < 2; ++side) {
        const short revents = fds[1 + 2 * i + static_cast<std::size_t>(side)].revents;
        if (revents != 0 && !Forward(pairs_[i], side, revents)) {
          dead.push_back(i);
          break;
        }
      }
    }
    for (auto it = dead.rbegin(); it != dead.rend(); ++it) {
      ::close(pairs_[*it].fd[0]);
      ::close(pairs_[*it].fd[1]);
      pairs_.erase(pairs_.begin() + static_cast<std::ptrdiff_t>(*it));
    }
  }
}

std::map<std::string, std::string> DirectoryFiles(const std::string& dir) {
  std::map<std::string, std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().filename().string().find(".tmp.") != std::string::npos)
      continue;
    out[fs::relative(e.path(), dir).string()] = io::ReadFile(e.path().string(), 256u << 20);
  }
  return out;
}

}  // namespace mapless::run

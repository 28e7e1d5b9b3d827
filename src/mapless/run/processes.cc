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
  return fd;
}

void Relay::CloseAll() {
  for (auto& [a, b] : pairs_) {
    ::close(a);
    ::close(b);
  }
  pairs_.clear();
  if (listener_ >= 0) ::close(listener_);
  listener_ = -1;
}

void Relay::Run() {
  char buffer[1 << 16];
  while (!stop_) {
    if (down_) {
      if (listener_ >= 0 || !pairs_.empty()) CloseAll();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    if (listener_ < 0) Listen();
    std::vector<pollfd> fds = {{listener_, POLLIN, 0}};
    for (const auto& [a, b] : pairs_) {
      fds.push_back({a, POLLIN, 0});
      fds.push_back({b, POLLIN, 0});
    }
    ::poll(fds.data(), fds.size(), 20);
    const std::size_t polled = pairs_.size();  // a pair accepted below waits for the next poll
    if (fds[0].revents & POLLIN) {
      const int in = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
      if (in >= 0) {
        const int out = Dial();
        if (out < 0) {
          ::close(in);
        } else {
          pairs_.emplace_back(in, out);
        }
      }
    }
    std::vector<std::size_t> dead;
    for (std::size_t i = 0; i < polled; ++i) {
      for (int side = 0; side < 2; ++side) {
        const pollfd& p = fds[1 + 2 * i + static_cast<std::size_t>(side)];
        if (!(p.revents & (POLLIN | POLLHUP | POLLERR))) continue;
        const int from = side == 0 ? pairs_[i].first : pairs_[i].second;
        const int to = side == 0 ? pairs_[i].second : pairs_[i].first;
        const ssize_t n = ::read(from, buffer, sizeof(buffer));
        bool ok = n > 0;
        for (ssize_t done = 0; ok && done < n;) {
          const ssize_t w = ::write(to, buffer + done, static_cast<std::size_t>(n - done));
          ok = w > 0;
          done += w > 0 ? w : 0;
        }
        if (!ok) dead.push_back(i);
      }
    }
    std::sort(dead.begin(), dead.end());
    dead.erase(std::unique(dead.begin(), dead.end()), dead.end());
    for (auto it = dead.rbegin(); it != dead.rend(); ++it) {
      ::close(pairs_[*it].first);
      ::close(pairs_[*it].second);
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

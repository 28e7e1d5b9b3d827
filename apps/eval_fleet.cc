// `mapless eval fleet` (fleet.h): the leader and each follower are processes of this program
// (/proc/self/exe), on loopback TCP; a follower whose link is cut goes through a TCP relay that
// this process runs and closes for the outage.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli_common.h"
#include "fleet.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/fleet/curve.h"
#include "mapless/io/atomic_file.h"

namespace mapless::app {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A free TCP port on 127.0.0.1 (bound and released; the leader binds it right after).
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

// A process of this program, its output to a log file.
class Child {
 public:
  Child(std::vector<std::string> args, std::string log)
      : args_(std::move(args)), log_(std::move(log)) {}
  void Start() {
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
      ::execv("/proc/self/exe", argv.data());
      ::_exit(127);
    }
    exited_ = false;
  }
  void Signal(int signal) {
    if (pid_ > 0 && !exited_) ::kill(pid_, signal);
  }
  // True once it has exited (status kept).
  bool Poll() {
    if (exited_ || pid_ <= 0) return exited_;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    return exited_;
  }
  void Wait(double seconds) {
    const auto t0 = Clock::now();
    while (!Poll() && Since(t0) < seconds)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (!Poll()) {
      Signal(SIGKILL);
      while (!Poll()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  int code() const { return code_; }

 private:
  std::vector<std::string> args_;
  std::string log_;
  pid_t pid_ = -1;
  bool exited_ = true;
  int code_ = -1;
};

// Forwards 127.0.0.1:listen_port to 127.0.0.1:target_port; Down() closes every connection and
// stops listening (connections are refused) until Up().
class Relay {
 public:
  Relay(int listen_port, int target_port) : listen_port_(listen_port), target_port_(target_port) {
    Listen();
    thread_ = std::thread([this] { Run(); });
  }
  ~Relay() {
    stop_ = true;
    thread_.join();
    CloseAll();
  }
  void Down() { down_ = true; }
  void Up() { down_ = false; }

 private:
  void Listen() {
    listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    const int one = 1;
    ::setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(listen_port_));
    if (::bind(listener_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
        ::listen(listener_, 16) != 0)
      throw InputError("eval fleet: the relay cannot listen on port " +
                       std::to_string(listen_port_));
  }
  int Dial() {
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
  void CloseAll() {
    for (auto& [a, b] : pairs_) {
      ::close(a);
      ::close(b);
    }
    pairs_.clear();
    if (listener_ >= 0) ::close(listener_);
    listener_ = -1;
  }
  void Run() {
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
      for (std::size_t i = 0; i < pairs_.size(); ++i) {
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
  int listen_port_;
  int target_port_;
  int listener_ = -1;
  std::vector<std::pair<int, int>> pairs_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> down_{false};
  std::thread thread_;
};

// The route's files (ignoring temporary files a killed writer left), by relative path.
std::map<std::string, std::string> RouteFiles(const std::string& dir) {
  std::map<std::string, std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().filename().string().find(".tmp.") != std::string::npos)
      continue;
    out[fs::relative(e.path(), dir).string()] = io::ReadFile(e.path().string(), 256u << 20);
  }
  return out;
}

}  // namespace

void AddFleetEvalOptions(CLI::App* eval, FleetEvalArgs* a) {
  eval->add_option("--followers", a->followers, "fleet: followers")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  eval->add_option("--method", a->method, "fleet: funnel or eigenspace")->capture_default_str();
  eval->add_option("--scenario", a->scenario,
                   "fleet: scenario (default table1_almost_straight / office_aliasing)");
  eval->add_option("--rate", a->rate, "fleet: simulated seconds per wall-clock second")
      ->capture_default_str()
      ->check(FiniteIn(0.1, 20.0));
  eval->add_option("--start-after", a->start_after_s,
                   "fleet: followers start this many seconds after the leader")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 600.0));
  eval->add_option("--kill-leader-at", a->kill_leader_at_s,
                   "fleet: kill the leader (SIGKILL) after this many seconds and start it again")
      ->check(FiniteIn(0.0, 3600.0));
  eval->add_option("--kill-follower-at", a->kill_follower_at_s,
                   "fleet: kill follower 1 after this many seconds and start it again")
      ->check(FiniteIn(0.0, 3600.0));
  eval->add_option("--link-down-at", a->link_down_at_s,
                   "fleet: cut the last follower's link after this many seconds ...")
      ->check(FiniteIn(0.0, 3600.0));
  eval->add_option("--link-down-for", a->link_down_for_s, "fleet: ... for this many seconds")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 600.0));
  eval->add_flag("--curve", a->curve, "fleet: CURVE keys for the leader and every follower");
  eval->add_option("--keep", a->keep, "fleet: keep the routes and logs in this directory");
}

void RunFleetEval(const FleetEvalArgs& a, bool json) {
  if (a.method != "funnel" && a.method != "eigenspace")
    throw InputError("--method " + a.method + ": must be funnel or eigenspace");
  const std::string scenario = !a.scenario.empty()    ? a.scenario
                               : a.method == "funnel" ? "table1_almost_straight"
                                                      : "office_aliasing";
  std::string work = a.keep;
  if (work.empty()) {
    char tmpl[] = "/tmp/mapless-fleet-XXXXXX";
    MAPLESS_CHECK(::mkdtemp(tmpl) != nullptr, "eval fleet: cannot make a temporary directory");
    work = tmpl;
  } else {
    MAPLESS_CHECK(!fs::exists(work) || fs::is_empty(work), "--keep " << work << ": not empty");
    fs::create_directories(work);
  }
  const int port = FreePort();
  const std::string endpoint = "tcp://127.0.0.1:" + std::to_string(port);
  std::vector<std::string> curve_leader, curve_follower;
  if (a.curve) {
    fleet::GenerateCurveKey(work + "/leader.key");
    fleet::GenerateCurveKey(work + "/follower.key");
    curve_leader = {"--curve-key", work + "/leader.key", "--curve-allow",
                    work + "/follower.key.pub"};
    curve_follower = {"--curve-key", work + "/follower.key", "--curve-leader",
                      work + "/leader.key.pub"};
  }
  const std::string rate = std::to_string(a.rate);
  std::vector<std::string> lead_args = {"mapless",  "lead",           "--source", "sim:" + scenario,
                                        "--route",  work + "/leader", "--bind",   endpoint,
                                        "--method", a.method,         "--rate",   rate};
  lead_args.insert(lead_args.end(), curve_leader.begin(), curve_leader.end());
  Child leader(lead_args, work + "/leader.log");
  std::unique_ptr<Relay> relay;
  int relay_port = 0;
  if (a.link_down_at_s > 0.0) {
    relay_port = FreePort();
    relay = std::make_unique<Relay>(relay_port, port);
  }
  std::vector<Child> followers;
  for (int i = 1; i <= a.followers; ++i) {
    const std::string name = "follower" + std::to_string(i);
    const bool relayed = relay && i == a.followers;
    std::vector<std::string> args = {
        "mapless",   "follow",
        "--connect", relayed ? "tcp://127.0.0.1:" + std::to_string(relay_port) : endpoint,
        "--source",  "sim:" + scenario,
        "--route",   work + "/" + name,
        "--rate",    rate,
        "--summary", work + "/" + name + ".json",
        "--seed",    std::to_string(a.seed + static_cast<std::uint64_t>(i))};
    args.insert(args.end(), curve_follower.begin(), curve_follower.end());
    followers.emplace_back(args, work + "/" + name + ".log");
  }
  StopCleanlyOnInterrupt();
  const auto t0 = Clock::now();
  leader.Start();
  bool started = false, leader_killed = false, follower_killed = false, link_cut = false,
       link_restored = false;
  int leader_restarts = 0, follower_restarts = 0;
  // Generous: the route at the given rate, twice, plus the start delay and the faults.
  const double limit_s = 900.0;
  try {
    while (true) {
      ThrowIfInterrupted();
      const double t = Since(t0);
      if (!started && t >= a.start_after_s) {
        for (Child& f : followers) f.Start();
        started = true;
      }
      if (a.kill_leader_at_s > 0.0 && !leader_killed && t >= a.kill_leader_at_s) {
        leader.Signal(SIGKILL);
        leader.Wait(5.0);
        leader.Start();
        leader_killed = true;
        ++leader_restarts;
        spdlog::info("eval fleet: killed the leader at {:.1f} s and started it again", t);
      }
      if (a.kill_follower_at_s > 0.0 && started && !follower_killed && t >= a.kill_follower_at_s) {
        followers[0].Signal(SIGKILL);
        followers[0].Wait(5.0);
        followers[0].Start();
        follower_killed = true;
        ++follower_restarts;
        spdlog::info("eval fleet: killed follower 1 at {:.1f} s and started it again", t);
      }
      if (relay && !link_cut && t >= a.link_down_at_s) {
        relay->Down();
        link_cut = true;
        spdlog::info("eval fleet: follower {}'s link down at {:.1f} s", a.followers, t);
      }
      if (relay && link_cut && !link_restored && t >= a.link_down_at_s + a.link_down_for_s) {
        relay->Up();
        link_restored = true;
        spdlog::info("eval fleet: follower {}'s link up again at {:.1f} s", a.followers, t);
      }
      bool all_done = started;
      for (Child& f : followers) all_done = f.Poll() && all_done;
      if (all_done && (!relay || link_restored || a.link_down_at_s > t)) break;
      if (t > limit_s) {
        spdlog::warn("eval fleet: time limit of {:.0f} s", limit_s);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  } catch (const Interrupted&) {
    for (Child& f : followers) f.Signal(SIGINT);
    leader.Signal(SIGINT);
    for (Child& f : followers) f.Wait(5.0);
    leader.Wait(5.0);
    throw;
  }
  for (Child& f : followers) {
    f.Signal(SIGINT);
    f.Wait(10.0);
  }
  leader.Signal(SIGINT);
  leader.Wait(10.0);
  relay.reset();

  const auto leader_files = RouteFiles(work + "/leader");
  nlohmann::json j;
  j["suite"] = "fleet";
  j["method"] = a.method;
  j["scenario"] = scenario;
  j["followers"] = a.followers;
  j["rate"] = a.rate;
  j["leader_restarts"] = leader_restarts;
  j["follower_restarts"] = follower_restarts;
  j["link_down_s"] = relay_port ? a.link_down_for_s : 0.0;
  j["curve"] = a.curve;
  j["wall_s"] = Since(t0);
  FILE* table = json ? stderr : stdout;
  std::fprintf(table, "%-10s %-9s %8s %8s %8s %8s %5s %5s %8s %9s %9s\n", "follower", "completed",
               "lateral", "final", "received", "applied", "gaps", "dups", "copy", "lat med",
               "lat p99");
  bool ok = true;
  for (int i = 1; i <= a.followers; ++i) {
    const std::string name = "follower" + std::to_string(i);
    nlohmann::json s;
    try {
      s = nlohmann::json::parse(io::ReadFile(work + "/" + name + ".json", 1 << 20));
    } catch (const std::exception&) {
      s["completed"] = false;
      s["reason"] = "no summary (see " + work + "/" + name + ".log)";
    }
    const auto copy_files = RouteFiles(work + "/" + name);
    const bool identical = !leader_files.empty() && copy_files == leader_files;
    // Gaps: records of the leader's route missing from the copy (every file of the leader's route
    // that the copy lacks or holds different bytes of); duplicates: records applied twice would
    // have been refused by the copy, so they are counted from the copy's refusals.
    int gaps = 0;
    for (const auto& [path, bytes] : leader_files) {
      const auto it = copy_files.find(path);
      gaps += it == copy_files.end() || it->second != bytes;
    }
    s["copy_identical"] = identical;
    s["gaps"] = gaps;
    s["duplicates_applied"] = s.value("rejected", 0);
    s["follower"] = i;
    s["restarted"] = follower_killed && i == 1;
    s["link_cut"] = relay_port && i == a.followers;
    const bool good =
        s.value("completed", false) && identical && gaps == 0 && s.value("rejected", 0) == 0;
    ok = ok && good;
    std::fprintf(table, "%-10s %-9s %7.3fm %7.3fm %8d %8d %5d %5d %8s %7.2fms %7.2fms\n",
                 name.c_str(), s.value("completed", false) ? "yes" : "NO",
                 s.value("lateral_rms_m", -1.0), s.value("final_error_m", -1.0),
                 s.value("records_received", 0), s.value("records_applied", 0), gaps,
                 s.value("rejected", 0), identical ? "same" : "DIFFERS",
                 s.value("latency_median_ms", -1.0), s.value("latency_p99_ms", -1.0));
    j["results"].push_back(s);
  }
  j["ok"] = ok;
  if (json) std::cout << j.dump() << "\n";
  if (a.keep.empty()) fs::remove_all(work);
  if (!ok)
    throw RunFailed(
        "eval fleet: a follower failed or its copy differs (logs: rerun with --keep DIR)");
}

}  // namespace mapless::app

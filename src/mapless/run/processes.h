// Processes and connections of an evaluation that runs mapless as several processes on loopback
// (fleet_eval.h): a child process of this program, a TCP relay whose link can be cut, a free port.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <map>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace mapless::run {

// Seconds of the steady clock since `t0`.
inline double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A free TCP port on 127.0.0.1 (bound and released; the caller binds it right after).
int FreePort();

// A process of `program` (default: this program), its output to a log file.
class Child {
 public:
  Child(std::vector<std::string> args, std::string log, std::string program = "/proc/self/exe")
      : args_(std::move(args)), log_(std::move(log)), program_(std::move(program)) {}
  void Start();
  void Signal(int signal);
  bool Poll();  // true once it has exited (status kept)
  // Waits up to `seconds` for it to exit, then kills it.
  void Wait(double seconds);
  int code() const { return code_; }

 private:
  std::vector<std::string> args_;
  std::string log_;
  std::string program_;
  pid_t pid_ = -1;
  bool exited_ = true;
  int code_ = -1;
};

// Forwards 127.0.0.1:listen_port to 127.0.0.1:target_port; Down() closes every connection and
// stops listening (connections are refused) until Up(). Non-blocking, with at most 64 KB held per
// direction: a peer that stops reading holds up only its own connection's other side, never the
// others, Down() or the destructor.
class Relay {
 public:
  Relay(int listen_port, int target_port);
  ~Relay();
  void Down() { down_ = true; }
  void Up() { down_ = false; }

 private:
  void Listen();
  int Dial();
  void CloseAll();
  void Run();
  int listen_port_;
  int target_port_;
  int listener_ = -1;
  struct Pair {
    int fd[2];               // the accepted connection, the one dialled to the target
    std::string pending[2];  // read from fd[i], not yet written to fd[1 - i]
  };
  bool Forward(Pair& pair, int side, short revents);
  std::vector<Pair> pairs_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> down_{false};
  std::thread thread_;
};

// A directory's files (ignoring the temporary files a killed writer left), by relative path.
std::map<std::string, std::string> DirectoryFiles(const std::string& dir);

}  // namespace mapless::run

// Progress of a long run on a terminal: "eval: 3/12 done, 1m20s left" on one line of stderr,
// rewritten in place. Silent when stderr is not a terminal (CI logs, pipes, files), so that logs
// and JSON output stay as they were.
#pragma once

#include <chrono>
#include <mutex>
#include <string>

namespace mapless::app {

class Progress {
 public:
  // `start`: when the work began (the time in the final line counts from there).
  Progress(std::string label, int total,
           std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now());
  ~Progress();  // clears the line
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // One more unit done (thread-safe); `what` names it.
  void Done(const std::string& what = "");
  // A stage of a fixed sequence (the demo): "demo: [2/4] eigenspace follower".
  void Stage(int index, const std::string& what);

 private:
  void Print(const std::string& text);
  std::string label_;
  int total_;
  int done_ = 0;
  bool tty_;
  bool printed_ = false;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
};

}  // namespace mapless::app

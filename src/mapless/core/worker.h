// A second thread that runs one job at a time for its owner (issue 44: RepeatSession's obstacle
// watch beside the frame's feature detection). It lives as long as its owner, so no thread is
// created per frame and the job's data stay on one core.
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace mapless {

class Worker {
 public:
  Worker();
  ~Worker();
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  // Runs `job` on the worker's thread. One job at a time: Wait() for it before the next.
  void Start(std::function<void()> job);
  // Until the job has run; rethrows what it threw. Does nothing when no job was started.
  void Wait();

 private:
  void Loop();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> job_;
  bool running_ = false;  // a job was started and has not been waited for
  bool done_ = false;     // ... and it has run
  bool quit_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace mapless

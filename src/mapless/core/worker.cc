#include "mapless/core/worker.h"

#include <utility>

#include "mapless/core/check.h"

namespace mapless {

Worker::Worker() : thread_([this] { Loop(); }) {}

Worker::~Worker() {
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return !running_ || done_; });
    quit_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void Worker::Start(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    MAPLESS_CHECK(!running_, "Worker::Start: the previous job was not waited for");
    job_ = std::move(job);
    running_ = true;
    done_ = false;
    error_ = nullptr;
  }
  changed_.notify_all();
}

void Worker::Wait() {
  std::unique_lock lock(mutex_);
  if (!running_) return;
  changed_.wait(lock, [this] { return done_; });
  running_ = false;
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void Worker::Loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return quit_ || (running_ && !done_); });
    if (quit_) return;
    std::function<void()> job = std::move(job_);
    lock.unlock();
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    error_ = error;
    done_ = true;
    changed_.notify_all();
  }
}

}  // namespace mapless

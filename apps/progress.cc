#include "progress.h"

#include <unistd.h>

#include <cstdio>

namespace mapless::app {
namespace {

std::string Duration(double s) {
  char buf[32];
  if (s >= 60.0)
    std::snprintf(buf, sizeof(buf), "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else
    std::snprintf(buf, sizeof(buf), "%ds", static_cast<int>(s + 0.5));
  return buf;
}

}  // namespace

Progress::Progress(std::string label, int total, std::chrono::steady_clock::time_point start)
    : label_(std::move(label)), total_(total), tty_(::isatty(STDERR_FILENO) == 1), start_(start) {}

Progress::~Progress() {
  if (printed_) std::fputs("\033[K", stderr);
}

void Progress::Print(const std::string& text) {
  if (!tty_) return;
  // Erase the line, write, and return to its start: the next progress line or log line writes
  // over it, so log lines and progress do not mix.
  std::fprintf(stderr, "\r\033[K%s\r", text.c_str());
  std::fflush(stderr);
  printed_ = true;
}

void Progress::Done(const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++done_;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string text = label_ + ": " + std::to_string(done_) + "/" + std::to_string(total_) + " done";
  if (done_ < total_)
    text += ", about " + Duration(elapsed / done_ * (total_ - done_)) + " left";
  else
    text += " in " + Duration(elapsed);
  if (!what.empty()) text += " (last: " + what + ")";
  Print(text);
}

void Progress::Stage(int index, const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  Print(label_ + ": [" + std::to_string(index) + "/" + std::to_string(total_) + "] " + what + " (" +
        Duration(elapsed) + " so far)");
}

}  // namespace mapless::app

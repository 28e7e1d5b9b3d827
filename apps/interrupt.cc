#include "interrupt.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>
#include <ctime>

#include "mapless/core/interrupt.h"

namespace mapless::app {
namespace {

std::atomic<int> g_signal{0};
std::atomic<bool> g_cooperative{false};
std::atomic<long long> g_first_ns{0};  // CLOCK_MONOTONIC of the first signal

long long MonotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);  // async-signal-safe
  return static_cast<long long>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

const char* Name(int signal) {
  return signal == SIGTERM  ? "terminated (SIGTERM)"
         : signal == SIGHUP ? "hung up (SIGHUP)"
                            : "interrupted (SIGINT)";
}

void Write(const char* text) {
  // write(2) is async-signal-safe; the result does not matter on the way out.
  const ssize_t unused = ::write(STDERR_FILENO, text, std::strlen(text));
  (void)unused;
}

extern "C" void OnSignal(int signal) {
  const long long now = MonotonicNs();
  const bool first = g_signal.exchange(signal) == 0;
  if (first) g_first_ns.store(now);
  RequestInterrupt();                         // every wait at the edges returns
  if (first && g_cooperative.load()) return;  // the run stops at its next frame
  // A repeat within a second is the same interrupt delivered twice (`timeout` sends its signal to
  // the command and to the command's process group), not the user insisting: a robot must still
  // get its zero velocity.
  if (!first && g_cooperative.load() && now - g_first_ns.load() < 1000000000LL) return;
  Write("mapless: "), Write(Name(signal)), Write("\n");
  ::_exit(128 + signal);
}

}  // namespace

Interrupted::Interrupted(int signal) : std::runtime_error(Name(signal)), signal_(signal) {}

void InstallInterruptHandlers() {
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGHUP, &action, nullptr);  // the terminal closed: the robot stops as on Ctrl-C
}

void StopCleanlyOnInterrupt() { g_cooperative.store(true); }

void ThrowIfInterrupted() {
  const int signal = g_signal.load();
  if (signal != 0 && g_cooperative.load()) throw Interrupted(signal);
}

int InterruptSignal() { return g_signal.load(); }

}  // namespace mapless::app

// Ctrl-C (SIGINT), SIGTERM and SIGHUP (the terminal closed) for the `mapless` command line.
//
// A command that writes while it runs (teach, repeat, navigate, sim drive, demo) calls
// StopCleanlyOnInterrupt() and then ThrowIfInterrupted() once per frame: the first signal makes
// that call throw Interrupted, so the run unwinds through its writers (routes and logs are
// finished, journals closed) and main() prints one line and exits with 130. Any other command, or
// a second signal a second or more after the first (a repeat within the second is the same
// interrupt delivered twice, as `timeout` does), ends the process at once with one line and exit
// code 130 (SIGINT) or 143
// (SIGTERM): nothing is half-written, since every file mapless writes is written atomically or
// journaled (docs/hardening.md).
#pragma once

#include <stdexcept>
#include <string>

namespace mapless::app {

class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int signal);
  int exit_code() const { return 128 + signal_; }

 private:
  int signal_;
};

// Installs the handlers (main() calls it first).
void InstallInterruptHandlers();
// From now on the first signal only sets a flag that ThrowIfInterrupted() reports.
void StopCleanlyOnInterrupt();
// Throws Interrupted when a signal has arrived since StopCleanlyOnInterrupt().
void ThrowIfInterrupted();
// The signal received (0: none).
int InterruptSignal();

}  // namespace mapless::app

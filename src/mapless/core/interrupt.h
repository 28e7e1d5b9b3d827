// The process-wide request to stop waiting (Ctrl-C, SIGTERM). The command line's signal handler
// sets it; every wait at the edges (a robot link waiting for a camera frame, a follower waiting
// for its leader) checks it at least every few milliseconds and returns, so that an interrupt is
// heard even when the clock a wait counts in has stopped (a simulated clock that no longer ticks).
//
// Setting and reading are lock-free atomics, safe in a signal handler.
#pragma once

namespace mapless {

void RequestInterrupt() noexcept;
bool InterruptRequested() noexcept;
// For tests.
void ClearInterrupt() noexcept;

}  // namespace mapless

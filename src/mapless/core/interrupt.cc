#include "mapless/core/interrupt.h"

#include <atomic>

namespace mapless {
namespace {

std::atomic<bool> g_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

}  // namespace

void RequestInterrupt() noexcept { g_requested.store(true); }
bool InterruptRequested() noexcept { return g_requested.load(); }
void ClearInterrupt() noexcept { g_requested.store(false); }

}  // namespace mapless

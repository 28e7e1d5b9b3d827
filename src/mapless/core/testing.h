// Helpers for the project's tests (header-only; not used by library code).
#pragma once

#include <functional>
#include <string>

#include "mapless/core/check.h"

namespace mapless::testing {

// The message of the InputError that `f` throws, or "" when it throws none.
inline std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace mapless::testing

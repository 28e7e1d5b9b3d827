// MAPLESS_CHECK: throws on a broken precondition (bad input, invalid options). Library code never
// aborts or prints; the app's main() turns the exception into one error line and a non-zero exit.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace mapless {

// Thrown for bad input that the user can fix (a field, a value, a file). Apps exit with code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mapless

// MAPLESS_CHECK(cond, "message " << value): throws mapless::InputError with the message.
#define MAPLESS_CHECK(cond, msg)                                \
  do {                                                          \
    if (!(cond)) {                                              \
      std::ostringstream mapless_check_stream_;                 \
      mapless_check_stream_ << msg;                             \
      throw ::mapless::InputError(mapless_check_stream_.str()); \
    }                                                           \
  } while (false)

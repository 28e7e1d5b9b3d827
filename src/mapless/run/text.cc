#include "mapless/run/text.h"

#include <cstdarg>
#include <cstdio>
#include <vector>

namespace mapless::run {

namespace {
std::string VFormat(const char* format, va_list args) {
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (n <= 0) return {};
  std::vector<char> buffer(static_cast<std::size_t>(n) + 1);
  std::vsnprintf(buffer.data(), buffer.size(), format, args);
  return std::string(buffer.data(), static_cast<std::size_t>(n));
}
}  // namespace

std::string Format(const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::string out = VFormat(format, args);
  va_end(args);
  return out;
}

void Appendf(std::string* out, const char* format, ...) {
  va_list args;
  va_start(args, format);
  *out += VFormat(format, args);
  va_end(args);
}

}  // namespace mapless::run

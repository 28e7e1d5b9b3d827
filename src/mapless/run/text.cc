#include "mapless/run/text.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <vector>

namespace mapless::run {

namespace {
__attribute__((format(printf, 1, 0))) std::string VFormat(const char* format, va_list args) {
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

std::vector<std::string> WrapWords(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    std::string line;
    std::size_t i = start;
    while (i < end) {
      const std::size_t space = std::min(text.find(' ', i), end);
      const std::string word = text.substr(i, space - i);
      if (!line.empty() && line.size() + 1 + word.size() > width) {
        lines.push_back(line);
        line.clear();
      }
      if (!word.empty()) line += (line.empty() ? "" : " ") + word;
      i = space + 1;
    }
    lines.push_back(line);
    start = end + 1;
  }
  return lines;
}

}  // namespace mapless::run

// printf-style text for the run layer's tables and lines.
#pragma once

#include <string>

namespace mapless::run {

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
// Appends to `out`.
void Appendf(std::string* out, const char* format, ...) __attribute__((format(printf, 2, 3)));

}  // namespace mapless::run

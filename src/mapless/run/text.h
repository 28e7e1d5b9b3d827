// printf-style text for the run layer's tables and lines.
#pragma once

#include <string>
#include <vector>

namespace mapless::run {

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
// Appends to `out`.
void Appendf(std::string* out, const char* format, ...) __attribute__((format(printf, 2, 3)));

// `text` in lines of at most `width` characters, broken at spaces (a word longer than `width`
// stands on a line of its own); a newline in the text starts a new line.
std::vector<std::string> WrapWords(const std::string& text, std::size_t width);

}  // namespace mapless::run

// Warnings from inside the library about input that was used, but not whole (a recording cut
// short). Libraries print nothing: they hand the line to the sink the program installed (the
// command line's is its log, "[warning] ..."); without one, warnings are dropped.
#pragma once

#include <functional>
#include <string>

namespace mapless {

using WarningSink = std::function<void(const std::string&)>;

void SetWarningSink(WarningSink sink);
void Warn(const std::string& line);

}  // namespace mapless

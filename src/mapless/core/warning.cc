#include "mapless/core/warning.h"

#include <mutex>
#include <utility>

namespace mapless {
namespace {

std::mutex& SinkMutex() {
  static std::mutex mutex;
  return mutex;
}
WarningSink& Sink() {
  static WarningSink sink;
  return sink;
}

}  // namespace

void SetWarningSink(WarningSink sink) {
  std::lock_guard<std::mutex> lock(SinkMutex());
  Sink() = std::move(sink);
}

void Warn(const std::string& line) {
  std::lock_guard<std::mutex> lock(SinkMutex());
  if (Sink()) Sink()(line);
}

}  // namespace mapless

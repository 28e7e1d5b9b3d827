#include "mapless/robot/middleware.h"

#include <stdexcept>

#include "mapless/core/check.h"

namespace mapless::robot {

void MiddlewareRegistry::Add(MiddlewareKind kind) {
  if (kind.name.empty() || !kind.open_link || !kind.serve || !kind.bench)
    throw std::logic_error("MiddlewareRegistry::Add: middleware '" + kind.name +
                           "' needs a name and all three functions");
  if (Find(kind.name) != nullptr)
    throw std::logic_error("MiddlewareRegistry::Add: middleware '" + kind.name +
                           "' registered twice");
  kinds_.push_back(std::move(kind));
}

const MiddlewareKind* MiddlewareRegistry::Find(const std::string& name) const {
  for (const MiddlewareKind& k : kinds_)
    if (k.name == name) return &k;
  return nullptr;
}

const MiddlewareKind& MiddlewareRegistry::For(const RobotFile& file) const {
  if (const MiddlewareKind* k = Find(file.middleware)) return *k;
  std::string built;
  for (const MiddlewareKind& k : kinds_) built += (built.empty() ? "" : ", ") + k.name;
  throw InputError(file.source + ": middleware " + file.middleware +
                   ", but this mapless was built without it (robot links in this build: " +
                   (built.empty() ? std::string("none") : built) +
                   "; install them with scripts/setup.sh --ros and build again)");
}

std::vector<std::string> MiddlewareRegistry::names() const {
  std::vector<std::string> out;
  out.reserve(kinds_.size());
  for (const MiddlewareKind& k : kinds_) out.push_back(k.name);
  return out;
}

}  // namespace mapless::robot

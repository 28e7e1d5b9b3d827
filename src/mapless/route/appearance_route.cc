#include "mapless/route/appearance_route.h"

namespace mapless::route {

double AppearanceRoute::SpacingM() const {
  if (images.size() < 2) return 0.0;
  return (images.back()->distance_m - images.front()->distance_m) /
         static_cast<double>(images.size() - 1);
}

void AppearanceRouteChannel::Publish(std::shared_ptr<const AppearanceRoute> route) {
  const std::lock_guard<std::mutex> lock(mutex_);
  latest_ = std::move(route);
}

std::shared_ptr<const AppearanceRoute> AppearanceRouteChannel::Latest() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return latest_;
}

}  // namespace mapless::route

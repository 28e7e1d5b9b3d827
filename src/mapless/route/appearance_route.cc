#include "mapless/route/appearance_route.h"

#include "mapless/core/check.h"

namespace mapless::route {

int AppearanceRoute::PlaceOf(int column) const {
  MAPLESS_CHECK(column >= 0 && column < columns(), "AppearanceRoute: column " << column);
  return column < size() ? column : views[static_cast<std::size_t>(column - size())]->place;
}

std::vector<int> AppearanceRoute::ColumnPlaces() const {
  std::vector<int> places(static_cast<std::size_t>(columns()));
  for (int c = 0; c < columns(); ++c) places[static_cast<std::size_t>(c)] = PlaceOf(c);
  return places;
}

std::vector<int> AppearanceRoute::ColumnsOf(int place) const {
  MAPLESS_CHECK(place >= 0 && place < size(), "AppearanceRoute: place " << place);
  std::vector<int> columns{place};
  if (static_cast<std::size_t>(place) < place_views.size())
    for (const int v : place_views[static_cast<std::size_t>(place)]) columns.push_back(size() + v);
  return columns;
}

const appearance::SubWindowEigenspace& AppearanceRoute::WindowsOf(int column) const {
  return column < size() ? images.at(static_cast<std::size_t>(column))->windows
                         : views.at(static_cast<std::size_t>(column - size()))->windows;
}

double AppearanceRoute::OffsetOf(int column) const {
  return column < size() ? 0.0 : views.at(static_cast<std::size_t>(column - size()))->offset_px;
}

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

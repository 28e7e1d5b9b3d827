// The route of the appearance-based method (Payá et al., Sections 2-3): the eigenspace of the
// route images (mean, basis, one projection per image) and, per image, its sub-window eigenspace
// and how far along the route it was taken. A leader teaching the route publishes a new immutable
// snapshot after each image it adds; followers take the latest snapshot and never see a model
// half-way through an update (AppearanceRouteChannel).
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "mapless/appearance/pca.h"
#include "mapless/appearance/subwindow.h"
#include "mapless/core/pose.h"

namespace mapless::route {

struct AppearanceRouteImage {
  appearance::SubWindowEigenspace windows;  // for steering
  double distance_m = 0.0;                  // odometry distance from the route start
  Pose2 odometry;                           // the leader's odometry when it was taken
};

// A view of a route image's place learned on a later visit (issue 45; `follow --learn`,
// navigation/appearance_experiences.h), with the sub-window shift that chains it to the route
// image: steering by it adds offset_px to its shift.
struct AppearanceRouteView {
  int place = 0;  // the route image it is a view of
  appearance::SubWindowEigenspace windows;
  double offset_px = 0.0;
};

struct AppearanceRoute {
  // projections: one column per route image, then one per learned view (views[i] is column
  // size() + i).
  appearance::Eigenspace space;
  // Shared between snapshots: an image's sub-windows never change once added.
  std::vector<std::shared_ptr<const AppearanceRouteImage>> images;
  std::vector<std::shared_ptr<const AppearanceRouteView>> views;
  // The views of each place (indices into views), in the order they were added; empty without
  // views.
  std::vector<std::vector<int>> place_views;
  bool complete = false;                                        // the leader has finished teaching
  int size() const { return static_cast<int>(images.size()); }  // places
  int columns() const { return size() + static_cast<int>(views.size()); }
  bool has_views() const { return !views.empty(); }
  // The place of projection column `column`, and the place of every column (for localization
  // over places).
  int PlaceOf(int column) const;
  std::vector<int> ColumnPlaces() const;
  // The columns of `place`: its route image's, then its views'.
  std::vector<int> ColumnsOf(int place) const;
  const appearance::SubWindowEigenspace& WindowsOf(int column) const;
  double OffsetOf(int column) const;  // 0 for a route image
  // Mean distance between consecutive route images, metres (0 with fewer than 2 images).
  double SpacingM() const;
};

// Thread-safe hand-over of route snapshots from a leader to followers in the same process.
class AppearanceRouteChannel {
 public:
  void Publish(std::shared_ptr<const AppearanceRoute> route);
  // The latest published snapshot (null before the first).
  std::shared_ptr<const AppearanceRoute> Latest() const;

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const AppearanceRoute> latest_;
};

}  // namespace mapless::route

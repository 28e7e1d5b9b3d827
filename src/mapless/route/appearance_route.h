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

struct AppearanceRoute {
  appearance::Eigenspace space;  // projections: one column per route image
  // Shared between snapshots: an image's sub-windows never change once added.
  std::vector<std::shared_ptr<const AppearanceRouteImage>> images;
  bool complete = false;  // the leader has finished teaching
  int size() const { return static_cast<int>(images.size()); }
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

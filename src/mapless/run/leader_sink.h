// A fleet leader as a route sink (teach.h): each piece of the route becomes a record, applied to
// the leader's own copy of the route (its route directory) and served to the followers at once.
#pragma once

#include <functional>

#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"
#include "mapless/run/teach.h"
#include "mapless/sim/simulation.h"

namespace mapless::run {

class LeaderSink : public RouteSink {
 public:
  // Both must outlive the sink.
  LeaderSink(fleet::RouteCopy& copy, fleet::LeaderServer& server) : copy_(copy), server_(server) {}
  void Start(const RouteStart& start) override { Serve(fleet::HeaderRecord(start)); }
  void Keyframe(const route::Keyframe& keyframe) override;
  void Image(const route::StoredAppearanceImage& image) override;
  void Finish() override { Serve(fleet::EndRecord()); }

 private:
  // Applied to the copy with what it was made from (not decoded again), then served.
  void Serve(fleet::Record record, std::optional<route::Keyframe> keyframe = std::nullopt,
             const cv::Mat& image_low = {});
  fleet::RouteCopy& copy_;
  fleet::LeaderServer& server_;
};

// A leader restarted on its route goes on where it stopped: `teacher` is given the route so far;
// on the simulator, the returned test says which frames of the teach drive are driven again
// without being rendered (empty: all are new).
std::function<bool(const sim::DriveFrame&)> ResumeLeader(const fleet::RouteCopy& copy,
                                                         fleet::RouteKind kind, Teacher* teacher);

}  // namespace mapless::run

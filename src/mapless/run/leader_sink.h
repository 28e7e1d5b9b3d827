// A fleet leader as a route sink (teach.h): each piece of the route becomes a record, applied to
// the leader's own copy of the route (its route directory) and served to the followers at once.
#pragma once

#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"
#include "mapless/run/teach.h"

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

}  // namespace mapless::run

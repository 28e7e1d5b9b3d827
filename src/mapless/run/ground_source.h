// `mapless ground --source`: the dominant plane of every frame of a source against the frame
// `step` frames later, as one JSON object per frame and, optionally, a mask file per frame.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "mapless/flow/flow.h"
#include "mapless/ground/dominant_plane.h"
#include "mapless/io/frame_source.h"
#include "mapless/io/output_dir.h"

namespace mapless::run {

struct GroundSourceOptions {
  flow::FlowOptions flow;
  ground::DominantPlaneOptions plane;
  int step = 1;        // F1 is this many frames after F0
  int max_frames = 0;  // 0: all
};

struct GroundSourceResult {
  int frames = 0;  // frames with a plane decided
  int found = 0;   // ... of which the plane was found
  double mean_fraction = 0.0;
};

// `name` names the source in errors; masks go to `masks` as NNNNNN.png when it is not null;
// `each_frame` runs before each frame (the command's interrupt check). Throws InputError when
// the frame size changes or no frame has one `step` later.
GroundSourceResult GroundOverSource(io::FrameSource& source, const std::string& name,
                                    const GroundSourceOptions& options, io::OutputDirectory* masks,
                                    const std::function<void(const nlohmann::json&)>& log,
                                    const std::function<void()>& each_frame);

}  // namespace mapless::run

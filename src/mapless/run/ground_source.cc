#include "mapless/run/ground_source.h"

#include <cstdio>
#include <deque>
#include <filesystem>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::run {

GroundSourceResult GroundOverSource(io::FrameSource& source, const std::string& name,
                                    const GroundSourceOptions& options, io::OutputDirectory* masks,
                                    const std::function<void(const nlohmann::json&)>& log,
                                    const std::function<void()>& each_frame) {
  std::deque<io::Frame> window;  // the last `step` + 1 frames
  GroundSourceResult result;
  double fraction_sum = 0.0;
  flow::FlowEstimator estimator(options.flow);
  io::Frame frame;
  while ((options.max_frames == 0 || result.frames < options.max_frames) && source.Next(&frame)) {
    if (each_frame) each_frame();
    if (!window.empty() && frame.image.size() != window.front().image.size())
      throw InputError(name + ": frame " + frame.name + " changes the image size");
    window.push_back(frame);
    if (static_cast<int>(window.size()) <= options.step) continue;
    const io::Frame& a = window.front();
    const cv::Mat field = estimator.Compute(a.image, window.back().image);
    const ground::DominantPlane plane = ground::DetectDominantPlane(field, options.plane);
    nlohmann::json j;
    j["frame"] = result.frames;
    j["name"] = a.name;
    j["t_s"] = ToSeconds(a.t_ns);
    j["found"] = plane.found;
    j["plane_fraction"] = plane.roi_fraction;
    if (masks != nullptr) {
      char file[32];
      std::snprintf(file, sizeof(file), "%06d.png", result.frames);
      io::WriteImageAtomic((std::filesystem::path(masks->path()) / file).string(), plane.mask);
      j["mask"] = file;
    }
    log(j);
    result.found += plane.found ? 1 : 0;
    fraction_sum += plane.roi_fraction;
    ++result.frames;
    window.pop_front();
  }
  if (result.frames == 0) {
    throw InputError(name + ": fewer than " + std::to_string(options.step + 1) +
                     " frames, so no frame has one " + std::to_string(options.step) + " later");
  }
  result.mean_fraction = fraction_sum / result.frames;
  return result;
}

}  // namespace mapless::run

// Issue 66's costs in `mapless bench`: the shift estimator on a 512x192 pair (the size of the
// Stromovka images) against stock ORB-500 on one such image, and a step of the sequence filter on
// a 1200-image route against DIS fast at 320x240, each measured in the same run. The frames are the
// simulator's outdoor route at 512x192 (real images are not shipped; the costs depend on the
// number of keypoints, which the outdoor scene's texture puts in the range of the real images').
#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "mapless/bench/bench.h"
#include "mapless/bench/timing.h"
#include "mapless/features/shift.h"
#include "mapless/localization/sequence_filter.h"
#include "mapless/sim/simulation.h"

namespace mapless::bench {

void BenchRealImageStages(int repeats, nlohmann::json* j) {
  sim::Scenario scenario = sim::LoadScenario("outdoor_70m");
  const double hfov = 2.0 * std::atan(0.5 * scenario.camera.model.width / scenario.camera.model.fx);
  scenario.camera.model = sim::CameraModel::FromFov(512, 192, hfov);
  std::vector<cv::Mat> frames;
  sim::DriveTaughtPath(scenario, {}, [&](const sim::DriveFrame& f) {
    if (f.index % 10 == 0 && frames.size() < 12) frames.push_back(f.image.clone());
  });
  const auto frame = [&](int i) -> const cv::Mat& {
    return frames[static_cast<std::size_t>(i) % frames.size()];
  };
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(500);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  (*j)["opencv_orb500_512x192_ms"] = MedianMs(repeats, 3, [&](int i) {
    orb->detectAndCompute(frame(i), cv::noArray(), keypoints, descriptors);
  });
  const features::ShiftOptions shift;
  const features::FeatureExtractor extractor(shift.features);
  (*j)["shift_pair_512x192_ms"] = MedianMs(repeats, 3, [&](int i) {
    features::EstimateShift(extractor.Extract(frame(i)), extractor.Extract(frame(i + 1)), shift);
  });
  std::vector<features::Features> taught;
  for (const cv::Mat& f : frames) taught.push_back(extractor.Extract(f));
  (*j)["shift_step_512x192_ms"] = MedianMs(repeats, 3, [&](int i) {
    const std::size_t k = static_cast<std::size_t>(i) % frames.size();
    features::EstimateShift(taught[k], extractor.Extract(frame(i + 1)), shift);
  });
  const double orb_ms = (*j)["opencv_orb500_512x192_ms"].get<double>();
  (*j)["shift_pair_over_orb500"] = (*j)["shift_pair_512x192_ms"].get<double>() / orb_ms;
  (*j)["shift_step_over_orb500"] = (*j)["shift_step_512x192_ms"].get<double>() / orb_ms;

  // The sequence filter: a route of 1200 images (the size of the Nordland evaluation), a camera
  // frame at 320x240 per step, against DIS fast on two such frames.
  const localization::SequenceFilterOptions filter_options;
  cv::Mat route(1200, filter_options.width * filter_options.height, CV_32F);
  cv::RNG rng(66);
  rng.fill(route, cv::RNG::NORMAL, 0.0, 1.0);
  localization::SequenceFilter filter(route, filter_options);
  std::vector<cv::Mat> small;
  for (int i = 0; i < 4; ++i) {
    cv::Mat f;
    cv::resize(frame(i), f, cv::Size(320, 240));
    small.push_back(f);
  }
  (*j)["sequence_filter_step_1200_ms"] = MedianMs(repeats, 3, [&](int i) {
    filter.Update(
        localization::SequenceDescriptor(small[static_cast<std::size_t>(i) % 4], filter_options));
  });
  auto dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
  cv::Mat flow;
  (*j)["opencv_dis_fast_real_320x240_ms"] =
      MedianMs(repeats, 3, [&](int) { dis->calc(small[0], small[1], flow); });
  (*j)["sequence_filter_step_over_dis_fast"] =
      (*j)["sequence_filter_step_1200_ms"].get<double>() /
      (*j)["opencv_dis_fast_real_320x240_ms"].get<double>();
}

}  // namespace mapless::bench

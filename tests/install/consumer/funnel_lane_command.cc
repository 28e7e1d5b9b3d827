// The sloped funnel lane's command for two images, with mapless as an installed library:
//   funnel_lane_command KEYFRAME.png CURRENT.png
// ORB features of both, matched, and the sloped funnel lane (Kassir et al., Section V) on the
// horizontal coordinates of the matches, relative to the image centre. Prints one line:
//   matches N std_ratio R slope_x X slope_y Y command left|right|straight v_mps V omega_radps W
#include <cstdio>
#include <exception>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "mapless/control/funnel_lane.h"
#include "mapless/features/features.h"
#include "mapless/io/image_file.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: funnel_lane_command KEYFRAME.png CURRENT.png\n");
    return 2;
  }
  try {
    namespace f = mapless::features;
    namespace c = mapless::control;
    const cv::Mat keyframe = mapless::io::ReadImage(argv[1], cv::IMREAD_GRAYSCALE, 16);
    const cv::Mat current = mapless::io::ReadImage(argv[2], cv::IMREAD_GRAYSCALE, 16);
    const f::FeatureExtractor extractor{f::FeatureOptions{}};
    const f::Features kf = extractor.Extract(keyframe);
    const f::Features cur = extractor.Extract(current);
    f::MatchOptions match;
    match.mutual = true;
    const std::vector<cv::DMatch> matches = f::MatchFeatures(cur, kf, match);
    const double cx = 0.5 * (keyframe.cols - 1);
    std::vector<c::FeaturePair> pairs;
    for (const cv::DMatch& m : matches)
      pairs.push_back({cur.keypoints[m.queryIdx].pt.x - cx, kf.keypoints[m.trainIdx].pt.x - cx});
    const c::SlopedFunnelLaneResult r = c::ComputeSlopedFunnelLane(pairs, {});
    std::printf(
        "matches %zu std_ratio %.3f slope_x %.3f slope_y %.3f command %s v_mps %.3f "
        "omega_radps %.3f\n",
        pairs.size(), r.std_ratio, r.slope_x, r.slope_y, c::TurnCommandName(r.command),
        r.twist.v_mps, r.twist.omega_radps);
    return r.ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "funnel_lane_command: %s\n", e.what());
    return 2;
  }
}

// `mapless shift REFERENCE CURRENT`: horizontal image displacement of CURRENT relative to
// REFERENCE, dx = x_in_current - x_in_reference for the same scene point.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_common.h"
#include "mapless/core/check.h"
#include "mapless/features/shift.h"
#include "mapless/io/image_file.h"

namespace mapless::app {

void AddShiftCommand(CLI::App* app) {
  struct Args {
    std::string reference;
    std::string current;
    bool json = false;
    std::string detector = features::DetectorTypeName(features::ShiftOptions{}.features.type);
    double ratio = features::ShiftOptions{}.matching.ratio;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "shift",
      "Horizontal shift of CURRENT relative to REFERENCE: dx = x_current - x_reference (px)");
  cmd->add_option("REFERENCE", args->reference, "Reference image")->required();
  cmd->add_option("CURRENT", args->current, "Current image")->required();
  cmd->add_flag("--json", args->json,
                "Print {\"dx_px\", \"matches\", \"inliers\", \"ok\"} as JSON");
  cmd->add_option("--detector", args->detector, "orb, akaze, akaze_upright, sift or akaze_sift")
      ->capture_default_str();
  cmd->add_option("--ratio", args->ratio,
                  "Ratio-test threshold (1: none; matches are cross-checked)")
      ->capture_default_str()
      ->check(FiniteIn(0.01, 1.0));
  cmd->callback([args] {
    features::ShiftOptions options;
    options.features.type = features::ParseDetectorType(args->detector);
    options.matching.ratio = args->ratio;
    options.Validate();
    const cv::Mat reference = ReadImageOrThrow(args->reference, cv::IMREAD_GRAYSCALE);
    const cv::Mat current = ReadImageOrThrow(args->current, cv::IMREAD_GRAYSCALE);
    // A shift in pixels compares the same image grid: different sizes have no common one.
    io::RequireSameSize(current, args->current, reference, args->reference);
    const features::ShiftEstimate e = features::EstimateShift(reference, current, options);
    if (!e.ok) spdlog::warn("shift: not ok: too few consistent matches ({})", e.matches);
    if (args->json) {
      nlohmann::json j;
      j["dx_px"] = e.dx_px;
      j["matches"] = e.matches;
      j["inliers"] = e.inliers;
      j["ok"] = e.ok;
      std::cout << j.dump() << "\n";
    } else {
      std::printf("dx_px %.2f  matches %d  inliers %d  %s\n", e.dx_px, e.matches, e.inliers,
                  e.ok ? "ok" : "NOT OK (too few consistent matches)");
    }
  });
}

}  // namespace mapless::app

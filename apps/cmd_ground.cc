// `mapless ground F0 F1 --out MASK.png`: the dominant plane (ground) of F0 from the flow F0 -> F1,
// as a 0/255 mask at F0's size; with --gt, its IoU against a labelled mask.
#include <spdlog/spdlog.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_common.h"
#include "mapless/core/check.h"
#include "mapless/flow/flow.h"
#include "mapless/ground/dominant_plane.h"
#include "mapless/io/atomic_file.h"

namespace mapless::app {

void AddGroundCommand(CLI::App* app) {
  struct Args {
    std::string first;
    std::string second;
    std::string out;
    std::string method = "dis_medium";
    std::string model = "homography";
    std::string truth;
    double epsilon_px = 0.4;
    double epsilon_relative = 0.4;
    double roi_top = 0.5;
    double fit_bottom = 0.5;
    double iou_top = 0.5;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "ground", "Dominant plane (ground) of F0 from the optical flow F0 -> F1, as a 0/255 mask");
  cmd->add_option("F0", args->first, "Frame at time t")->required();
  cmd->add_option("F1", args->second, "Frame at time t+1")->required();
  cmd->add_option("--out", args->out, "Write the mask (PNG, F0's size)");
  cmd->add_option("--method", args->method, "Flow: dis, dis_medium, farneback or lk")
      ->capture_default_str();
  cmd->add_option("--model", args->model, "Planar flow model: homography or affine (the paper's)")
      ->capture_default_str();
  cmd->add_option("--epsilon", args->epsilon_px, "Tolerance |u - u_hat| in pixels (Eq. 5)")
      ->capture_default_str()
      ->check(FiniteIn(1e-3, 100.0));
  cmd->add_option("--epsilon-relative", args->epsilon_relative,
                  "Tolerance grows by this fraction of |u_hat| (0: the paper's fixed epsilon)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 10.0));
  cmd->add_option("--roi-top", args->roi_top,
                  "Region of interest: rows below this fraction of the height (0: whole image)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 0.95));
  cmd->add_option("--fit-bottom", args->fit_bottom,
                  "RANSAC draws from the bottom fraction of the region of interest only (1: all)")
      ->capture_default_str()
      ->check(FiniteIn(0.01, 1.0));
  cmd->add_option("--gt", args->truth, "Labelled ground mask (255 = ground): print IoU as JSON");
  cmd->add_option("--iou-top", args->iou_top, "IoU over the rows below this fraction of the height")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 0.99));
  cmd->callback([args] {
    RefuseOutputOverInputs(args->out, "--out", {args->first, args->second, args->truth});
    flow::FlowOptions flow_options;
    flow_options.method = flow::ParseFlowMethod(args->method);
    ground::DominantPlaneOptions options;
    options.model = ground::ParsePlaneModel(args->model);
    options.epsilon_px = args->epsilon_px;
    options.epsilon_relative = args->epsilon_relative;
    options.roi_top_fraction = args->roi_top;
    options.fit_bottom_fraction = args->fit_bottom;
    options.Validate();
    const cv::Mat a = ReadImageOrThrow(args->first, cv::IMREAD_GRAYSCALE);
    const cv::Mat b = ReadImageOrThrow(args->second, cv::IMREAD_GRAYSCALE);
    RequireSameSize(b, args->second, a, args->first);
    const cv::Mat field = flow::ComputeFlow(a, b, flow_options);
    const ground::DominantPlane plane = ground::DetectDominantPlane(field, options);
    if (!plane.found) {
      spdlog::warn("ground: no dominant plane: it covers {:.0f}% of the region of interest",
                   100.0 * plane.roi_fraction);
    }
    if (!args->out.empty()) io::WriteImageAtomic(args->out, plane.mask);
    if (!args->truth.empty()) {
      const cv::Mat truth = ReadImageOrThrow(args->truth, cv::IMREAD_GRAYSCALE);
      RequireSameSize(truth, args->truth, a, args->first);
      const cv::Mat gt = truth > 127;
      const int top = static_cast<int>(args->iou_top * a.rows);
      nlohmann::json j;
      j["found"] = plane.found;
      j["plane_fraction"] = plane.roi_fraction;
      j["iou"] = ground::MaskIoU(plane.mask, gt, cv::Rect(0, top, a.cols, a.rows - top));
      std::cout << j.dump() << "\n";
    }
    if (args->out.empty() && args->truth.empty())
      throw InputError("ground: nothing to do: give --out, --gt or both");
  });
}

}  // namespace mapless::app

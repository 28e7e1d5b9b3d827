// `mapless flow A B --out F.flo`: dense optical flow from A to B (Middlebury .flo), and its
// end-point error when ground truth is given.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_common.h"
#include "mapless/core/check.h"
#include "mapless/flow/flow.h"
#include "mapless/io/flo.h"
#include "mapless/io/image_file.h"

namespace mapless::app {

void AddFlowCommand(CLI::App* app) {
  struct Args {
    std::string first;
    std::string second;
    std::string out;
    std::string method = "dis";
    std::string truth;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand("flow", "Dense optical flow from image A to image B");
  cmd->add_option("A", args->first, "First image")->required();
  cmd->add_option("B", args->second, "Second image")->required();
  cmd->add_option("--out", args->out, "Write the flow as Middlebury .flo");
  cmd->add_option("--flow", args->method, "dis (DIS fast), dis_medium, farneback or lk")
      ->capture_default_str();
  AddOldName(cmd, "--method", "--flow", &args->method);
  cmd->add_option("--gt", args->truth,
                  "Ground truth (.flo, or KITTI .png): print the end-point error as JSON");
  cmd->callback([args] {
    RefuseOutputOverInputs(args->out, "--out", {args->first, args->second, args->truth});
    flow::FlowOptions options;
    options.method = flow::ParseFlowMethod(args->method);
    const cv::Mat a = ReadImageOrThrow(args->first, cv::IMREAD_GRAYSCALE);
    const cv::Mat b = ReadImageOrThrow(args->second, cv::IMREAD_GRAYSCALE);
    io::RequireSameSize(b, args->second, a, args->first);
    const cv::Mat field = flow::ComputeFlow(a, b, options);
    if (!args->out.empty()) {
      io::WriteFlo(args->out, field);
      spdlog::info("flow: wrote {} ({}x{}, {})", args->out, field.cols, field.rows, args->method);
    }
    if (!args->truth.empty()) {
      cv::Mat valid;
      const cv::Mat truth = io::ReadFlowFile(args->truth, &valid);
      io::RequireSameSize(truth, args->truth, a, args->first);
      const flow::FlowError e = flow::EndPointError(field, truth, valid);
      nlohmann::json j;
      j["method"] = args->method;
      j["epe_px"] = e.mean_epe_px;
      j["median_epe_px"] = e.median_epe_px;
      j["pixels"] = e.count;
      std::cout << j.dump() << "\n";
    }
    if (args->out.empty() && args->truth.empty())
      throw InputError("flow: nothing to do: give --out, --gt or both");
  });
}

}  // namespace mapless::app

// `mapless ground F0 F1 --out MASK.png`: the dominant plane (ground) of F0 from the flow F0 -> F1,
// as a 0/255 mask at F0's size; with --gt, its IoU against a labelled mask.
// `mapless ground --source REC`: the same for every frame of a recording, video or image folder
// against the frame --step frames later, one JSON line per frame and, with --out-dir, the masks.
#include <spdlog/spdlog.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/flow/flow.h"
#include "mapless/ground/dominant_plane.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/io/output_dir.h"
#include "mapless/run/ground_source.h"
#include "recording_args.h"

namespace mapless::app {

namespace {

struct GroundArgs {
  std::string first;
  std::string second;
  std::string out;
  std::string method = "dis_medium";
  std::string model = "homography";
  std::string truth;
  double epsilon_px = 0.4;
  double epsilon_relative = 0.4;
  double nearer_fraction = 0.5;
  double roi_top = 0.5;
  double fit_bottom = 0.5;
  double iou_top = 0.5;
  // A recording, video or image folder as the source.
  std::string source;
  recording::PlaybackOptions playback;
  double fps = 10.0;
  int step = 1;
  int max_frames = 0;
  std::string out_dir;
  std::string log = "-";
};

ground::DominantPlaneOptions PlaneOptions(const GroundArgs& args) {
  ground::DominantPlaneOptions options;
  options.model = ground::ParsePlaneModel(args.model);
  options.epsilon_px = args.epsilon_px;
  options.epsilon_relative = args.epsilon_relative;
  options.nearer_fraction = args.nearer_fraction;
  options.roi_top_fraction = args.roi_top;
  options.fit_bottom_fraction = args.fit_bottom;
  options.Validate();
  return options;
}

void GroundOfTwoFiles(const GroundArgs& args) {
  RefuseOutputOverInputs(args.out, "--out", {args.first, args.second, args.truth});
  flow::FlowOptions flow_options;
  flow_options.method = flow::ParseFlowMethod(args.method);
  const ground::DominantPlaneOptions options = PlaneOptions(args);
  const cv::Mat a = ReadImageOrThrow(args.first, cv::IMREAD_GRAYSCALE);
  const cv::Mat b = ReadImageOrThrow(args.second, cv::IMREAD_GRAYSCALE);
  io::RequireSameSize(b, args.second, a, args.first);
  const cv::Mat field = flow::ComputeFlow(a, b, flow_options);
  const ground::DominantPlane plane = ground::DetectDominantPlane(field, options);
  if (!plane.found) {
    spdlog::warn("ground: no dominant plane: it covers {:.0f}% of the region of interest",
                 100.0 * plane.roi_fraction);
  }
  if (!args.out.empty()) io::WriteImageAtomic(args.out, plane.mask);
  if (!args.truth.empty()) {
    const cv::Mat truth = ReadImageOrThrow(args.truth, cv::IMREAD_GRAYSCALE);
    io::RequireSameSize(truth, args.truth, a, args.first);
    const cv::Mat gt = truth > 127;
    const int top = static_cast<int>(args.iou_top * a.rows);
    nlohmann::json j;
    j["found"] = plane.found;
    j["plane_fraction"] = plane.roi_fraction;
    j["iou"] = ground::MaskIoU(plane.mask, gt, cv::Rect(0, top, a.cols, a.rows - top));
    std::cout << j.dump() << "\n";
  }
  if (args.out.empty() && args.truth.empty())
    throw InputError("ground: nothing to do: give --out, --gt or both");
}

// Frame i against frame i + step, for every frame that has one.
void GroundOfSource(const GroundArgs& args) {
  if (!args.first.empty() || !args.second.empty())
    throw InputError("ground: give F0 F1 or --source, not both");
  if (!args.out.empty() || !args.truth.empty())
    throw InputError("ground --source: --out and --gt are for F0 F1; use --out-dir for masks");
  RefuseOutputOverInputs(args.log == "-" ? "" : args.log, "--log",
                         {args.source, args.playback.poses});
  RefuseOutputOverInputs(args.out_dir, "--out-dir", {args.source, args.playback.poses});
  run::GroundSourceOptions options;
  options.flow.method = flow::ParseFlowMethod(args.method);
  options.plane = PlaneOptions(args);
  options.step = args.step;
  options.max_frames = args.max_frames;
  recording::PlaybackOptions playback = args.playback;
  playback.fps = args.fps;
  const std::unique_ptr<io::FrameSource> source = recording::OpenSource(args.source, playback);
  std::unique_ptr<io::OutputDirectory> out;
  if (!args.out_dir.empty()) {
    out = std::make_unique<io::OutputDirectory>(args.out_dir, false, "ground masks", "");
  }
  JsonLines log(args.log);
  StopCleanlyOnInterrupt();
  const run::GroundSourceResult r = run::GroundOverSource(
      *source, args.source, options, out.get(), [&log](const nlohmann::json& j) { log.Write(j); },
      ThrowIfInterrupted);
  if (out) out->Commit();
  spdlog::info(
      "ground: {} frames, dominant plane found in {} ({:.0f}%), mean {:.0f}% of the "
      "region of interest",
      r.frames, r.found, 100.0 * r.found / r.frames, 100.0 * r.mean_fraction);
}

}  // namespace

void AddGroundCommand(CLI::App* app) {
  auto args = std::make_shared<GroundArgs>();
  CLI::App* cmd = app->add_subcommand(
      "ground",
      "Dominant plane (ground) of F0 from the optical flow F0 -> F1, as a 0/255 mask; or of "
      "every frame of a --source");
  cmd->add_option("F0", args->first, "Frame at time t");
  cmd->add_option("F1", args->second, "Frame at time t+1");
  cmd->add_option("--out", args->out, "Write the mask (PNG, F0's size)");
  cmd->add_option("--flow", args->method, "Optical flow: dis, dis_medium, farneback or lk")
      ->capture_default_str();
  AddOldName(cmd, "--method", "--flow", &args->method);
  cmd->add_option("--model", args->model, "Planar flow model: homography or affine (the paper's)")
      ->capture_default_str();
  cmd->add_option("--epsilon", args->epsilon_px, "Tolerance |u - u_hat| in pixels (Eq. 5)")
      ->capture_default_str()
      ->check(FiniteIn(1e-3, 100.0));
  cmd->add_option("--epsilon-relative", args->epsilon_relative,
                  "Tolerance grows by this fraction of |u_hat| (0: the paper's fixed epsilon)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 10.0));
  cmd->add_option("--nearer-fraction", args->nearer_fraction,
                  "Tolerance along the planar flow (moving more: nearer than the ground), as a "
                  "fraction of the tolerance (1: the paper's circle)")
      ->capture_default_str()
      ->check(FiniteIn(0.01, 1.0));
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
  cmd->add_option("--source", args->source,
                  "Instead of F0 F1: every frame of a recording (.mcap, .bag), video or image "
                  "folder, against the frame --step later; one JSON line per frame");
  AddPlaybackOptions(cmd, &args->playback);
  cmd->add_option("--fps", args->fps, "--source: frame rate of image folders (timestamps)")
      ->capture_default_str()
      ->check(FiniteIn(io::kMinFolderFps, io::kMaxFolderFps));
  cmd->add_option("--step", args->step, "--source: F1 is this many frames after F0")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  cmd->add_option("--max-frames", args->max_frames, "--source: stop after this many (0: all)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100'000'000));
  cmd->add_option("--out-dir", args->out_dir,
                  "--source: write each frame's mask as DIR/NNNNNN.png (a new or empty directory)");
  cmd->add_option("--log", args->log, "--source: the JSON lines (- for stdout)")
      ->capture_default_str();
  cmd->callback([args] {
    if (!args->source.empty()) {
      GroundOfSource(*args);
      return;
    }
    if (args->first.empty() || args->second.empty())
      throw InputError("ground: give two frames F0 F1, or --source");
    GroundOfTwoFiles(*args);
  });
}

}  // namespace mapless::app

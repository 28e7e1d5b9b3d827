#include "mapless/run/traces.h"

#include <algorithm>
#include <cmath>

#include "mapless/report/pictures.h"

namespace mapless::run {
namespace {

report::PlotSpec CommandsPlot(const std::vector<double>& t, const std::vector<double>& v,
                              const std::vector<double>& omega) {
  report::PlotSpec p{"Commands over time", "time (s)", "v (m/s), omega (rad/s)", {}, 640, 240};
  p.series.push_back({t, v, "#1f77b4", "v (m/s)", false, false});
  p.series.push_back({t, omega, "#ff7f0e", "omega (rad/s)", false, false});
  return p;
}

// Frames at 20%, 50% and 80% of `expected` frames: the chosen frames of the pictures.
bool Chosen(int frame, std::size_t expected) {
  for (double f : {0.2, 0.5, 0.8})
    if (frame == static_cast<int>(f * static_cast<double>(expected))) return true;
  return false;
}

}  // namespace

void RepeatTrace::Step(const cv::Mat& image, const navigation::RepeatStep& s) {
  t_.push_back(frame_ * dt_s_);
  v_.push_back(s.command.v_mps);
  omega_.push_back(s.command.omega_radps);
  slope_x_.push_back(s.sloped.slope_x);
  slope_y_.push_back(s.sloped.slope_y);
  const auto& keyframes = taught_->route->keyframes;
  if (Chosen(frame_, expected_frames_) && s.destination >= 0 &&
      s.destination < static_cast<int>(keyframes.size())) {
    pictures_.push_back(
        {report::MatchPicture(image, keyframes[static_cast<std::size_t>(s.destination)].thumbnail,
                              s.current_px, s.destination_px,
                              "frame " + std::to_string(frame_) + ", keyframe " +
                                  std::to_string(s.destination) + ": " + std::to_string(s.matches) +
                                  " matches, slopes " + Fixed(s.sloped.slope_x, 2) + " / " +
                                  Fixed(s.sloped.slope_y, 2)),
         "frame " + std::to_string(frame_) + " (left) and keyframe " +
             std::to_string(s.destination) + " (right)"});
  }
  ++frame_;
}

void RepeatTrace::AddTo(RunSection* section) const {
  section->plots.push_back(CommandsPlot(t_, v_, omega_));
  // The standard funnel lane has no slopes (they stay 0): no plot of them.
  const auto nonzero = [](double x) { return x != 0.0; };
  if (std::none_of(slope_x_.begin(), slope_x_.end(), nonzero) &&
      std::none_of(slope_y_.begin(), slope_y_.end(), nonzero)) {
    AddPictures(section);
    return;
  }
  report::PlotSpec slopes{
      "Funnel-lane slopes (Kassir et al., Eq. 6-7)", "time (s)", "slope", {}, 640, 220};
  slopes.series.push_back({t_, slope_x_, "#9467bd", "slope x", false, false});
  slopes.series.push_back({t_, slope_y_, "#8c564b", "slope y", true, false});
  section->plots.push_back(slopes);
  AddPictures(section);
}

void RepeatTrace::AddPictures(RunSection* section) const {
  section->pictures.insert(section->pictures.end(), pictures_.begin(), pictures_.end());
  section->pictures_caption =
      "Chosen frames: the current image next to its destination keyframe (its stored thumbnail), "
      "with the matched features joined.";
}

void EigenspaceTrace::Step(const navigation::FollowerStep& step) {
  t_.push_back(frame_ * dt_s_);
  v_.push_back(step.command.v_mps);
  omega_.push_back(step.command.omega_radps);
  index_.push_back(step.index >= 0 ? step.index : std::nan(""));
  probability_.push_back(step.index >= 0 ? step.probability : std::nan(""));
  beliefs_.push_back(step.belief);
  ++frame_;
}

void EigenspaceTrace::AddTo(RunSection* section) const {
  section->plots.push_back(CommandsPlot(t_, v_, omega_));
  report::PlotSpec loc{"Localization over time", "time (s)", "route image", {}, 640, 240};
  loc.series.push_back({t_, index_, "#1f77b4", "localized route image", false, true});
  section->plots.push_back(loc);
  report::PlotSpec prob{"Belief mass around the estimate", "time (s)", "probability", {}, 640, 200};
  prob.series.push_back({t_, probability_, "#2ca02c", "probability", false, false});
  section->plots.push_back(prob);
  section->pictures.push_back({report::BeliefPicture(beliefs_, {}), "the belief over time"});
  section->pictures_caption =
      "The Markov belief over the route images (upwards, by index) against the frame (to the "
      "right), each frame's column scaled to its own peak (square root: the colour bar); brighter "
      "is more likely. The route grows while the leader teaches.";
}

void PotentialTrace::Step(const cv::Mat& image, const navigation::PotentialStep& step) {
  t_.push_back(frame_ * dt_s_);
  v_.push_back(step.command.v_mps);
  omega_.push_back(step.command.omega_radps);
  plane_.push_back(step.plane_found ? step.plane_fraction : std::nan(""));
  if ((frame_ == 15 || frame_ == 60 || frame_ == 120) && !step.plane_mask.empty()) {
    pictures_.push_back(
        {report::PlanePicture(image, step.plane_mask, step.theta_rad,
                              "frame " + std::to_string(frame_) +
                                  (step.leg == 0 ? ", to the destination" : ", homing") +
                                  ", force " + Fixed(step.theta_rad * 180.0 / kPi, 0) + " deg"),
         "frame " + std::to_string(frame_)});
  }
  ++frame_;
}

void PotentialTrace::AddTo(RunSection* section) const {
  section->plots.push_back(CommandsPlot(t_, v_, omega_));
  report::PlotSpec frac{"Dominant plane", "time (s)", "fraction of the image", {}, 640, 200};
  frac.series.push_back({t_, plane_, "#2ca02c", "plane fraction", false, false});
  section->plots.push_back(frac);
  section->pictures.insert(section->pictures.end(), pictures_.begin(), pictures_.end());
  section->pictures_caption =
      "Chosen frames: the dominant plane (green: free ground; red: obstacles) and the direction "
      "of the control force (arrow).";
}

}  // namespace mapless::run

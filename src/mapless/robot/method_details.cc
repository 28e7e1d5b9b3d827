// What each method shows of a decision (methods.h): its status fields and its debug picture.
#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/robot/methods.h"
#include "mapless/robot/status.h"

namespace mapless::robot {

namespace {
const cv::Scalar kGreen(0, 220, 0), kRed(0, 0, 255), kYellow(0, 220, 255), kCyan(255, 255, 0);
}  // namespace

// ---- repeat: matched features and the funnel-lane slopes ---------------------------------------

void RepeatDetail::Fields(nlohmann::json* j) const {
  const navigation::RepeatStep& s = step;
  (*j)["destination"] = s.destination;
  (*j)["matches"] = s.matches;
  (*j)["tracked"] = s.tracked;
  (*j)["switched"] = s.switched;
  if (s.recovered_from >= 0) (*j)["recovered_from"] = s.recovered_from;
  if (s.carrying_on) (*j)["carrying_on"] = true;
  if (s.avoiding) (*j)["avoiding"] = true;
  if (s.view > 0) (*j)["view"] = s.view;  // a learned view of the destination (experiences)
  if (s.learned >= 0) {
    (*j)["learned"] = s.learned;
    (*j)["learned_why"] = s.learned_why;
  }
  (*j)["std_ratio"] = s.switching.std_ratio;
  (*j)["ed_px"] = s.switching.ed_px;
  if (s.local_scale.ok) (*j)["local_scale"] = s.local_scale.ratio;
  (*j)["slope_x"] = s.sloped.slope_x;
  (*j)["slope_y"] = s.sloped.slope_y;
  if (s.obstacle.observed) (*j)["obstacle_fraction"] = s.obstacle.blocked_fraction;
}

void RepeatDetail::Draw(cv::Mat* out, double scale, std::vector<std::string>* lines) const {
  const navigation::RepeatStep& s = step;
  // Matched features, coloured by their side in the destination keyframe (the funnel lanes' left
  // and right sets), and a line to where each is in the keyframe.
  const float cx = static_cast<float>(out->cols / scale) / 2.0f;
  for (std::size_t i = 0; i < s.current_px.size(); ++i) {
    const cv::Point2f c = s.current_px[i] * scale;
    const bool left = i < s.destination_px.size() && s.destination_px[i].x < cx;
    if (i < s.destination_px.size())
      cv::line(*out, c, s.destination_px[i] * scale, cv::Scalar(120, 120, 120), 1);
    cv::circle(*out, c, 3, left ? kGreen : kCyan, 1, cv::LINE_AA);
  }
  lines->push_back("keyframe " + std::to_string(s.destination) + "  matches " +
                   std::to_string(s.matches) + "  tracked " + std::to_string(s.tracked));
  lines->push_back("slope_x " + FixedText(s.sloped.slope_x, 3) + "  slope_y " +
                   FixedText(s.sloped.slope_y, 3) + "  StdRatio " +
                   FixedText(s.switching.std_ratio, 2));
}

// ---- navigate: the dominant plane and the potential's force ------------------------------------

void PotentialDetail::Fields(nlohmann::json* j) const {
  const navigation::PotentialStep& s = step;
  (*j)["plane_found"] = s.plane_found;
  (*j)["plane_fraction"] = s.plane_fraction;
  (*j)["free_ahead"] = s.free_ahead;
  (*j)["ground_mismatch"] = s.ground_mismatch;
  (*j)["theta_d_deg"] = RadToDeg(s.theta_d_rad);
  (*j)["theta_deg"] = RadToDeg(s.theta_rad);
  (*j)["force"] = {s.force[0], s.force[1]};
  (*j)["leg"] = s.leg;
}

void PotentialDetail::Draw(cv::Mat* out, double, std::vector<std::string>* lines) const {
  const navigation::PotentialStep& s = step;
  if (!s.plane_mask.empty()) {
    cv::Mat mask;
    cv::resize(s.plane_mask, mask, out->size(), 0, 0, cv::INTER_NEAREST);
    cv::Mat tint(out->size(), CV_8UC3, kGreen);
    cv::Mat blended;
    cv::addWeighted(*out, 0.6, tint, 0.4, 0.0, blended);
    blended.copyTo(*out, mask);
  }
  const double f = std::hypot(s.force[0], s.force[1]);
  if (f > 1e-9) {
    const cv::Point2d centre(out->cols / 2.0, out->rows / 2.0);
    const double len = 0.3 * out->rows;
    const cv::Point2d tip = centre + cv::Point2d(s.force[0] / f * len, -s.force[1] / f * len);
    cv::arrowedLine(*out, centre, tip, kRed, 2, cv::LINE_AA);
  }
  lines->push_back("plane " + FixedText(s.plane_fraction, 2) + "  ahead " +
                   FixedText(s.free_ahead, 2) + "  theta " + FixedText(RadToDeg(s.theta_rad), 1));
}

// ---- follow: the localization and the sub-window fit ------------------------------------------

void FollowerDetail::Fields(nlohmann::json* j) const {
  const navigation::FollowerStep& s = step;
  (*j)["index"] = s.index;
  (*j)["probability"] = s.probability;
  (*j)["target"] = s.target;
  if (s.carrying_on) (*j)["carrying_on"] = true;
  if (s.steering.ok) {
    (*j)["fit"] = s.steering.fit;
    (*j)["shift_px"] = s.steering.shift_px;
    (*j)["confidence"] = s.steering.confidence;
  }
  if (s.obstacle.observed) (*j)["obstacle_fraction"] = s.obstacle.blocked_fraction;
}

void FollowerDetail::Draw(cv::Mat* out, double scale, std::vector<std::string>* lines) const {
  const navigation::FollowerStep& s = step;
  lines->push_back("image " + std::to_string(s.index) + "  p " + FixedText(s.probability, 2) +
                   "  target " + std::to_string(s.target));
  if (s.steering.ok) {
    lines->push_back("fit " + s.steering.fit + "  shift " + FixedText(s.steering.shift_px, 1) +
                     " px  conf " + FixedText(s.steering.confidence, 2));
    const double x = out->cols / 2.0 + s.steering.shift_px * scale;
    cv::line(*out, cv::Point2d(x, 0), cv::Point2d(x, out->rows), kYellow, 1);
  }
}

}  // namespace mapless::robot

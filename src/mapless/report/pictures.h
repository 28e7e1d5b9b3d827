// Pictures of chosen frames and of a run, for the report and its PNG files: the current image next
// to its keyframe with the matched features and the funnel-lane slopes; the dominant-plane mask
// and the potential's force over the camera image; the eigenspace belief over time; a line plot
// drawn with OpenCV (the PNG twin of an SVG plot). Pure drawing: each returns a BGR image.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/report/svg.h"

namespace mapless::report {

// `current` (grey or BGR) and the keyframe's thumbnail (scaled to the current image's size) side
// by side; a line joins each matched pair (current_px[i] in the current image, keyframe_px[i] in
// full-size keyframe pixels); `text` is written on top (e.g. the slopes).
cv::Mat MatchPicture(const cv::Mat& current, const cv::Mat& keyframe_thumbnail,
                     const std::vector<cv::Point2f>& current_px,
                     const std::vector<cv::Point2f>& keyframe_px, const std::string& text);

// The camera image with the dominant plane (mask > 0, any size: scaled to the image) tinted green
// and the obstacles red; an arrow from the bottom centre in the direction `theta_rad` of the
// control force (positive to the left); `text` on top.
cv::Mat PlanePicture(const cv::Mat& image, const cv::Mat& plane_mask, double theta_rad,
                     const std::string& text);

// The belief over route images (rows of `beliefs`, one per frame; rows may grow as the route
// does) as a heat map: time to the right, route image upwards; `truth[i]` (route image nearest to
// the robot, or -1) as a white dot; with axes (frame, route image) and a colour bar.
cv::Mat BeliefPicture(const std::vector<std::vector<float>>& beliefs, const std::vector<int>& truth,
                      int height_px = 240);

// A CSS colour "#rrggbb" as an OpenCV BGR colour; anything else is grey.
cv::Scalar CssToBgr(const std::string& css);

// The PNG twin of LinePlotSvg (CSS colours as #rrggbb).
cv::Mat LinePlotPicture(const PlotSpec& spec);

}  // namespace mapless::report

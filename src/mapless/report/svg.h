// Plots for the HTML report as inline SVG text: a top-down view of a simulated world with paths
// (like viz::DrawTopDown, but vector), and line plots of series over time or distance. Pure: each
// function returns the <svg> element as a string; no fonts, scripts or links outside it.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "mapless/core/pose.h"
#include "mapless/sim/world.h"

namespace mapless::report {

struct Series {
  std::vector<double> x;
  std::vector<double> y;          // same length as x; non-finite values break the line
  std::string color = "#1f77b4";  // any CSS colour
  std::string label;
  bool dashed = false;
  bool points = false;  // dots instead of a line
};

struct PlotSpec {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<Series> series;
  int width_px = 640;
  int height_px = 240;
};

// A line plot with axes, ticks, a legend and a title; an empty plot says "no data".
std::string LinePlotSvg(const PlotSpec& spec);

struct PathSpec {
  std::vector<Pose2> poses;
  std::string color = "#d62728";
  std::string label;
  double width_px = 2.0;
};

// The world from above (walls, boxes, cylinders, posters), a metre grid, the paths (start circle,
// end arrow), the markers (destinations) as stars, a legend and a 1 m scale bar. x to the right,
// y up (REP-103 world frame).
std::string TopDownSvg(const sim::World& world, const std::vector<PathSpec>& paths,
                       const std::vector<Eigen::Vector2d>& markers = {}, int max_side_px = 640);

// Text made safe for HTML and SVG (& < > " ').
std::string Escape(const std::string& text);

}  // namespace mapless::report

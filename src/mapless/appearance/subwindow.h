// Sub-window eigenspaces for appearance-based steering (Section 3 of Payá et al.): from each route
// image, N' sub-windows are cut from its central band by scanning horizontally with a fixed step,
// and compressed by a K'-component PCA of that image's own windows. At run time five sub-windows
// A-E of the current image are projected into the matched route image's sub-window eigenspace and
// the stored windows nearest to them (inside spheres whose common radius yields a fixed total
// number of correspondences, seven in the paper) become the input of the steering controller
// (control/subwindow_steering.h).
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "mapless/appearance/pca.h"

namespace mapless::appearance {

struct SubWindowOptions {
  int window_width_px = 16;  // sub-window width in the low-resolution image, px
  int step_px = 1;           // horizontal scan step, px; N' = (width - window_width) / step + 1
  double band_top = 0.1;     // central band: top row as a fraction of the image height
  double band_bottom = 0.9;  // bottom row (exclusive) as a fraction of the image height
  int dimensions = 8;        // K', components of each image's sub-window eigenspace
  int correspondences = 7;   // total correspondences kept for the five query windows (>= 5)
  void Validate() const;
};

// One route image's sub-window eigenspace: `space.projections` holds the N' stored windows
// (column i = the window starting at x = i * step).
struct SubWindowEigenspace {
  Eigenspace space;
  int image_width = 0;
  int image_height = 0;
  int windows() const { return space.images(); }
};

// Number of sub-windows N' for an image `image_width` px wide.
int SubWindowCount(int image_width, const SubWindowOptions& options);

// The stored-window index at which each of the five query windows A-E is cut from the current
// image: evenly spread from the first to the last window, so A..E are the windows a perfectly
// aligned view would match, (N' - 1)/4 indices apart.
std::array<int, 5> QueryWindowIndices(int window_count);

// The window starting at x = index * step in the central band, as a vector.
Vector SubWindow(const cv::Mat& low_resolution, int index, const SubWindowOptions& options);

// Builds the sub-window eigenspace of one low-resolution route image (CV_32FC1).
SubWindowEigenspace BuildSubWindowEigenspace(const cv::Mat& low_resolution,
                                             const SubWindowOptions& options);

// A correspondence: query window (0 = A ... 4 = E) and the stored window it falls near.
struct SubWindowMatch {
  int query = 0;
  int stored = 0;
  float distance = 0.0F;
};

// Projects the five query windows of `current` (low resolution, same size as the route image)
// into `route` and returns `options.correspondences` stored windows near them: each query
// window's nearest, then the nearest of the rest overall. (The paper grows five spheres of a
// common radius until they hold seven windows; then a query window in a smooth region, whose
// neighbours all lie close, takes every correspondence and the fit has one abscissa.)
std::vector<SubWindowMatch> MatchSubWindows(const SubWindowEigenspace& route,
                                            const cv::Mat& current,
                                            const SubWindowOptions& options);

}  // namespace mapless::appearance

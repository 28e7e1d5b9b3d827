#include "mapless/appearance/subwindow.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"

namespace mapless::appearance {
namespace {

struct Band {
  int top = 0;
  int rows = 0;
};

Band CentralBand(int image_height, const SubWindowOptions& options) {
  Band band;
  band.top = static_cast<int>(std::lround(options.band_top * image_height));
  const int bottom = static_cast<int>(std::lround(options.band_bottom * image_height));
  band.rows = std::max(1, bottom - band.top);
  return band;
}

}  // namespace

void SubWindowOptions::Validate() const {
  MAPLESS_CHECK(window_width_px >= 2,
                "SubWindowOptions.window_width_px = " << window_width_px << "; must be >= 2");
  MAPLESS_CHECK(step_px >= 1, "SubWindowOptions.step_px = " << step_px << "; must be >= 1");
  MAPLESS_CHECK(band_top >= 0.0 && band_top < band_bottom && band_bottom <= 1.0,
                "SubWindowOptions.band_top/band_bottom = " << band_top << "/" << band_bottom
                                                           << "; need 0 <= top < bottom <= 1");
  MAPLESS_CHECK(dimensions >= 1,
                "SubWindowOptions.dimensions = " << dimensions << "; must be >= 1");
  MAPLESS_CHECK(correspondences >= 5,
                "SubWindowOptions.correspondences = " << correspondences << "; must be >= 5");
}

int SubWindowCount(int image_width, const SubWindowOptions& options) {
  if (image_width < options.window_width_px) return 0;
  return (image_width - options.window_width_px) / options.step_px + 1;
}

std::array<int, 5> QueryWindowIndices(int window_count) {
  std::array<int, 5> indices{};
  for (int i = 0; i < 5; ++i) {
    indices[static_cast<std::size_t>(i)] =
        static_cast<int>(std::lround(i * (window_count - 1) / 4.0));
  }
  return indices;
}

Vector SubWindow(const cv::Mat& low_resolution, int index, const SubWindowOptions& options) {
  const Band band = CentralBand(low_resolution.rows, options);
  const int x0 = index * options.step_px;
  Vector window(static_cast<Eigen::Index>(band.rows) * options.window_width_px);
  Eigen::Index k = 0;
  for (int r = 0; r < band.rows; ++r) {
    const float* row = low_resolution.ptr<float>(band.top + r) + x0;
    for (int c = 0; c < options.window_width_px; ++c) window(k++) = row[c];
  }
  return window;
}

SubWindowEigenspace BuildSubWindowEigenspace(const cv::Mat& low_resolution,
                                             const SubWindowOptions& options) {
  options.Validate();
  MAPLESS_CHECK(low_resolution.type() == CV_32FC1, "sub-windows: expected a CV_32FC1 image");
  const int count = SubWindowCount(low_resolution.cols, options);
  MAPLESS_CHECK(count >= 5, "sub-windows: an image " << low_resolution.cols << " px wide gives "
                                                     << count << " windows of "
                                                     << options.window_width_px
                                                     << " px; need at least 5");
  const Band band = CentralBand(low_resolution.rows, options);
  Matrix data(static_cast<Eigen::Index>(band.rows) * options.window_width_px, count);
  for (int i = 0; i < count; ++i) data.col(i) = SubWindow(low_resolution, i, options);
  SubWindowEigenspace route;
  route.space = BatchPcaGram(data, options.dimensions);
  route.image_width = low_resolution.cols;
  route.image_height = low_resolution.rows;
  return route;
}

std::vector<SubWindowMatch> MatchSubWindows(const SubWindowEigenspace& route,
                                            const cv::Mat& current,
                                            const SubWindowOptions& options) {
  MAPLESS_CHECK(current.type() == CV_32FC1 && current.cols == route.image_width &&
                    current.rows == route.image_height,
                "sub-windows: current image " << current.cols << "x" << current.rows
                                              << " does not match the route image "
                                              << route.image_width << "x" << route.image_height);
  const int count = route.windows();
  const std::array<int, 5> query = QueryWindowIndices(count);
  std::vector<SubWindowMatch> all;
  all.reserve(static_cast<std::size_t>(5 * count));
  for (int q = 0; q < 5; ++q) {
    const Vector f =
        route.space.Project(SubWindow(current, query[static_cast<std::size_t>(q)], options));
    for (int i = 0; i < count; ++i) {
      all.push_back({q, i, (route.space.projections.col(i) - f).norm()});
    }
  }
  const auto nearer = [](const SubWindowMatch& a, const SubWindowMatch& b) {
    if (a.distance != b.distance) return a.distance < b.distance;
    if (a.query != b.query) return a.query < b.query;
    return a.stored < b.stored;
  };
  // Each query window's nearest stored window first, then the nearest of the rest overall.
  std::vector<SubWindowMatch> kept;
  std::vector<bool> used(all.size(), false);
  for (int q = 0; q < 5; ++q) {
    std::size_t best = all.size();
    for (std::size_t i = static_cast<std::size_t>(q * count);
         i < static_cast<std::size_t>((q + 1) * count); ++i) {
      if (best == all.size() || nearer(all[i], all[best])) best = i;
    }
    kept.push_back(all[best]);
    used[best] = true;
  }
  std::vector<SubWindowMatch> rest;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (!used[i]) rest.push_back(all[i]);
  }
  const std::size_t more =
      std::min(rest.size(), static_cast<std::size_t>(std::max(0, options.correspondences - 5)));
  std::partial_sort(rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(more), rest.end(),
                    nearer);
  kept.insert(kept.end(), rest.begin(), rest.begin() + static_cast<std::ptrdiff_t>(more));
  std::sort(kept.begin(), kept.end(), nearer);
  all.swap(kept);
  return all;
}

}  // namespace mapless::appearance

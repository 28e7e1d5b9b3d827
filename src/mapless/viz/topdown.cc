#include "mapless/viz/topdown.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace mapless::viz {

cv::Mat DrawTopDown(const sim::World& world, const std::vector<TopDownPath>& paths,
                    const std::vector<Eigen::Vector2d>& markers, const TopDownOptions& options) {
  Eigen::Vector4d b = sim::FootprintBounds(world);
  for (const auto& path : paths) {
    for (const Pose2& p : path.poses) {
      b[0] = std::min(b[0], p.x_m);
      b[1] = std::min(b[1], p.y_m);
      b[2] = std::max(b[2], p.x_m);
      b[3] = std::max(b[3], p.y_m);
    }
  }
  for (const auto& m : markers) {
    b[0] = std::min(b[0], m.x());
    b[1] = std::min(b[1], m.y());
    b[2] = std::max(b[2], m.x());
    b[3] = std::max(b[3], m.y());
  }
  b[0] -= options.margin_m;
  b[1] -= options.margin_m;
  b[2] += options.margin_m;
  b[3] += options.margin_m;
  const double span = std::max(b[2] - b[0], b[3] - b[1]);
  const double ppm = std::min(options.pixels_per_m, options.max_side_px / span);
  const int width = std::max(200, static_cast<int>(std::ceil((b[2] - b[0]) * ppm)));
  const int height = std::max(200, static_cast<int>(std::ceil((b[3] - b[1]) * ppm))) + 40;
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(250, 250, 250));
  auto px = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround((x - b[0]) * ppm)),
                     static_cast<int>(std::lround((b[3] - y) * ppm)));
  };
  // Grid: every metre, or every 10^k metres so that there are at most 100 lines each way.
  double grid_m = 1.0;
  while (span / grid_m > 100.0) grid_m *= 10.0;
  for (double x = std::ceil(b[0] / grid_m) * grid_m; x <= b[2]; x += grid_m) {
    cv::line(img, px(x, b[1]), px(x, b[3]), cv::Scalar(232, 232, 232), 1);
  }
  for (double y = std::ceil(b[1] / grid_m) * grid_m; y <= b[3]; y += grid_m) {
    cv::line(img, px(b[0], y), px(b[2], y), cv::Scalar(232, 232, 232), 1);
  }
  for (const sim::WorldObject& o : world.objects) {
    switch (o.kind) {
      case sim::ObjectKind::kWall:
        cv::line(img, px(o.a.x(), o.a.y()), px(o.b.x(), o.b.y()), cv::Scalar(60, 60, 60), 3,
                 cv::LINE_AA);
        break;
      case sim::ObjectKind::kBox: {
        const double c = std::cos(o.yaw_rad);
        const double s = std::sin(o.yaw_rad);
        std::vector<cv::Point> poly;
        for (const auto& [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
          const double lx = 0.5 * u * o.size_m.x();
          const double ly = 0.5 * v * o.size_m.y();
          poly.push_back(px(o.center.x() + c * lx - s * ly, o.center.y() + s * lx + c * ly));
        }
        cv::fillConvexPoly(img, poly, cv::Scalar(170, 190, 210), cv::LINE_AA);
        cv::polylines(img, poly, true, cv::Scalar(90, 90, 90), 1, cv::LINE_AA);
        break;
      }
      case sim::ObjectKind::kCylinder:
        cv::circle(img, px(o.center.x(), o.center.y()),
                   std::max(2, static_cast<int>(o.radius_m * ppm)), cv::Scalar(180, 200, 170),
                   cv::FILLED, cv::LINE_AA);
        break;
      case sim::ObjectKind::kPoster: {
        const double c = std::cos(o.yaw_rad + kPi / 2);
        const double s = std::sin(o.yaw_rad + kPi / 2);
        const double hw = 0.5 * o.size_m.x();
        cv::line(img, px(o.center.x() - c * hw, o.center.y() - s * hw),
                 px(o.center.x() + c * hw, o.center.y() + s * hw), cv::Scalar(200, 80, 200), 2,
                 cv::LINE_AA);
        break;
      }
    }
  }
  for (const auto& m : markers) {
    cv::drawMarker(img, px(m.x(), m.y()), cv::Scalar(0, 140, 0), cv::MARKER_STAR, 14, 2);
  }
  int legend_x = 10;
  // Draw in reverse so that the first path (usually the reference) ends up on top.
  for (auto it = paths.rbegin(); it != paths.rend(); ++it) {
    const TopDownPath& path = *it;
    std::vector<cv::Point> pts;
    for (const Pose2& p : path.poses) pts.push_back(px(p.x_m, p.y_m));
    if (pts.size() >= 2) cv::polylines(img, pts, false, path.color, 2, cv::LINE_AA);
    if (!path.poses.empty()) {
      const Pose2& e = path.poses.back();
      cv::circle(img, pts.front(), 5, path.color, 2, cv::LINE_AA);
      cv::arrowedLine(img, pts.back(),
                      px(e.x_m + 0.4 * std::cos(e.theta_rad), e.y_m + 0.4 * std::sin(e.theta_rad)),
                      path.color, 2, cv::LINE_AA, 0, 0.3);
    }
  }
  for (const TopDownPath& path : paths) {
    if (path.label.empty()) continue;
    cv::line(img, cv::Point(legend_x, height - 18), cv::Point(legend_x + 25, height - 18),
             path.color, 3);
    cv::putText(img, path.label, cv::Point(legend_x + 30, height - 13), cv::FONT_HERSHEY_SIMPLEX,
                0.45, cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
    legend_x += 40 + 9 * static_cast<int>(path.label.size());
  }
  // Scale bar: 1 m.
  const int bar = static_cast<int>(std::lround(ppm));
  cv::line(img, cv::Point(width - bar - 15, height - 18), cv::Point(width - 15, height - 18),
           cv::Scalar(0, 0, 0), 3);
  cv::putText(img, "1 m", cv::Point(width - bar - 15, height - 25), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return img;
}

}  // namespace mapless::viz

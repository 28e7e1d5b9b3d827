#include "mapless/report/pictures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace mapless::report {
namespace {

cv::Mat Bgr(const cv::Mat& image) {
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else
    out = image.clone();
  return out;
}

void Caption(cv::Mat* img, const std::string& text) {
  if (text.empty()) return;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.42, 1, &baseline);
  cv::rectangle(*img, cv::Rect(0, 0, std::min(img->cols, size.width + 8), size.height + 8),
                cv::Scalar(255, 255, 255), cv::FILLED);
  cv::putText(*img, text, cv::Point(4, size.height + 3), cv::FONT_HERSHEY_SIMPLEX, 0.42,
              cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
}

}  // namespace

cv::Scalar CssToBgr(const std::string& css) {
  unsigned r = 0, g = 0, b = 0;
  if (css.size() == 7 && css[0] == '#' &&
      std::sscanf(css.c_str() + 1, "%2x%2x%2x", &r, &g, &b) == 3)
    return cv::Scalar(b, g, r);
  return cv::Scalar(128, 128, 128);
}

cv::Mat MatchPicture(const cv::Mat& current, const cv::Mat& keyframe_thumbnail,
                     const std::vector<cv::Point2f>& current_px,
                     const std::vector<cv::Point2f>& keyframe_px, const std::string& text) {
  const cv::Mat cur = Bgr(current);
  cv::Mat key;
  if (keyframe_thumbnail.empty())
    key = cv::Mat(cur.size(), CV_8UC3, cv::Scalar(200, 200, 200));
  else
    cv::resize(Bgr(keyframe_thumbnail), key, cur.size(), 0, 0, cv::INTER_LINEAR);
  cv::Mat out;
  cv::hconcat(cur, key, out);
  const float dx = static_cast<float>(cur.cols);
  for (std::size_t i = 0; i < current_px.size() && i < keyframe_px.size(); ++i) {
    const cv::Scalar c((37 * i) % 200 + 55, (91 * i) % 200 + 55, (53 * i) % 200 + 55);
    const cv::Point2f a = current_px[i];
    const cv::Point2f b = keyframe_px[i] + cv::Point2f(dx, 0.0F);
    cv::line(out, a, b, c, 1, cv::LINE_AA);
    cv::circle(out, a, 3, c, 1, cv::LINE_AA);
    cv::circle(out, b, 3, c, 1, cv::LINE_AA);
  }
  cv::line(out, cv::Point(cur.cols, 0), cv::Point(cur.cols, cur.rows), cv::Scalar(255, 255, 255),
           2);
  Caption(&out, text);
  return out;
}

cv::Mat PlanePicture(const cv::Mat& image, const cv::Mat& plane_mask, double theta_rad,
                     const std::string& text) {
  cv::Mat out = Bgr(image);
  if (!plane_mask.empty()) {
    cv::Mat mask;
    cv::resize(plane_mask, mask, out.size(), 0, 0, cv::INTER_NEAREST);
    cv::Mat tint(out.size(), CV_8UC3, cv::Scalar(0, 0, 220));  // obstacle: red
    tint.setTo(cv::Scalar(0, 200, 0), mask > 0);               // dominant plane: green
    cv::addWeighted(out, 0.6, tint, 0.4, 0.0, out);
  }
  const cv::Point base(out.cols / 2, out.rows - 8);
  const double len = 0.35 * out.rows;
  // Image x grows to the right; a force to the left (positive theta) points left.
  const cv::Point tip(base.x - static_cast<int>(std::lround(len * std::sin(theta_rad))),
                      base.y - static_cast<int>(std::lround(len * std::cos(theta_rad))));
  cv::arrowedLine(out, base, tip, cv::Scalar(255, 255, 0), 3, cv::LINE_AA, 0, 0.25);
  Caption(&out, text);
  return out;
}

namespace {

void Label(cv::Mat* img, const std::string& text, cv::Point at, double scale = 0.38) {
  cv::putText(*img, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(40, 40, 40), 1,
              cv::LINE_AA);
}

// The heat map inside axes: route image (upwards) against frame (to the right), with ticks, and a
// colour bar from no belief to the frame's peak.
cv::Mat WithBeliefAxes(const cv::Mat& map, int frames, int images) {
  const int left = 46, bottom = 30, top = 8, right = 74;
  cv::Mat out(map.rows + top + bottom, map.cols + left + right, CV_8UC3, cv::Scalar(255, 255, 255));
  map.copyTo(out(cv::Rect(left, top, map.cols, map.rows)));
  cv::rectangle(out, cv::Rect(left - 1, top - 1, map.cols + 2, map.rows + 2),
                cv::Scalar(90, 90, 90));
  for (int k = 0; k <= 4; ++k) {
    const int frame = frames * k / 4;
    const int x = left + static_cast<int>(static_cast<double>(map.cols) * k / 4.0);
    cv::line(out, {x, top + map.rows}, {x, top + map.rows + 4}, cv::Scalar(90, 90, 90));
    Label(&out, std::to_string(frame), {x - 8, top + map.rows + 15});
    const int image = (images - 1) * k / 4;
    const int y =
        top + map.rows - 1 - static_cast<int>(static_cast<double>(map.rows - 1) * k / 4.0);
    cv::line(out, {left - 4, y}, {left, y}, cv::Scalar(90, 90, 90));
    Label(&out, std::to_string(image), {4, y + 4});
  }
  Label(&out, "frame", {left + map.cols / 2 - 14, top + map.rows + 27});
  Label(&out, "image", {2, top + 10});
  // The colour bar: viridis from 0 (no belief) to 1 (the frame's peak), square-root scaled.
  const int bx = left + map.cols + 12;
  cv::Mat ramp(map.rows, 1, CV_8UC1);
  for (int r = 0; r < map.rows; ++r)
    ramp.at<std::uint8_t>(r, 0) =
        static_cast<std::uint8_t>(255 - 255 * r / std::max(1, map.rows - 1));
  cv::Mat bar;
  cv::applyColorMap(ramp, bar, cv::COLORMAP_VIRIDIS);
  cv::resize(bar, bar, cv::Size(12, map.rows), 0, 0, cv::INTER_NEAREST);
  bar.copyTo(out(cv::Rect(bx, top, 12, map.rows)));
  Label(&out, "peak", {bx + 15, top + 8});
  Label(&out, "0", {bx + 15, top + map.rows});
  Label(&out, "sqrt", {bx + 15, top + map.rows / 2});
  return out;
}

}  // namespace

cv::Mat BeliefPicture(const std::vector<std::vector<float>>& beliefs, const std::vector<int>& truth,
                      int height_px) {
  std::size_t images = 1;
  for (const auto& b : beliefs) images = std::max(images, b.size());
  const int cols = std::max<int>(1, static_cast<int>(beliefs.size()));
  cv::Mat grid(static_cast<int>(images), cols, CV_8UC1, cv::Scalar(0));
  for (int t = 0; t < static_cast<int>(beliefs.size()); ++t) {
    const auto& b = beliefs[static_cast<std::size_t>(t)];
    float peak = 0.0F;
    for (float v : b) peak = std::max(peak, v);
    if (!(peak > 0.0F)) continue;
    for (std::size_t i = 0; i < b.size(); ++i) {
      // Square root: the tails of the belief stay visible next to its peak.
      const double v = std::sqrt(std::max(0.0F, b[i]) / peak);
      grid.at<std::uint8_t>(static_cast<int>(images - 1 - i), t) =
          static_cast<std::uint8_t>(std::lround(255.0 * v));
    }
  }
  cv::Mat colour;
  cv::applyColorMap(grid, colour, cv::COLORMAP_VIRIDIS);
  const int width = std::clamp(cols * 2, 200, 900);
  cv::Mat out;
  // The heat map inside `height_px`: the axes' labels take 38 rows of it.
  const int map_height = std::max(40, height_px - 38);
  cv::resize(colour, out, cv::Size(width, map_height), 0, 0, cv::INTER_NEAREST);
  const double sx = static_cast<double>(width) / cols;
  const double sy = static_cast<double>(map_height) / static_cast<double>(images);
  for (std::size_t t = 0; t < truth.size() && t < static_cast<std::size_t>(cols); ++t) {
    if (truth[t] < 0) continue;
    cv::circle(out,
               cv::Point(static_cast<int>((static_cast<double>(t) + 0.5) * sx),
                         static_cast<int>((static_cast<double>(images) - 0.5 - truth[t]) * sy)),
               1, cv::Scalar(255, 255, 255), cv::FILLED);
  }
  return WithBeliefAxes(out, cols, static_cast<int>(images));
}

cv::Mat LinePlotPicture(const PlotSpec& spec) {
  const int w = spec.width_px, h = spec.height_px;
  const int left = 58, right = 12, top = spec.title.empty() ? 12 : 26, bottom = 44;
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Series& s : spec.series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  if (!(x0 <= x1)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 - x0 < 1e-9) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-9) y0 -= 0.5, y1 += 0.5;
  const double pw = w - left - right, ph = h - top - bottom;
  const auto P = [&](double x, double y) {
    return cv::Point2d(left + (x - x0) / (x1 - x0) * pw, top + (y1 - y) / (y1 - y0) * ph);
  };
  cv::rectangle(img, cv::Point(left, top),
                cv::Point(left + static_cast<int>(pw), top + static_cast<int>(ph)),
                cv::Scalar(136, 136, 136));
  char buf[64];
  for (int k = 0; k <= 4; ++k) {
    const double y = y0 + (y1 - y0) * k / 4.0;
    const cv::Point2d p = P(x0, y);
    cv::line(img, cv::Point2d(left, p.y), cv::Point2d(left + pw, p.y), cv::Scalar(228, 228, 228));
    std::snprintf(buf, sizeof(buf), "%.2f", y);
    cv::putText(img, buf, cv::Point2d(4, p.y + 4), cv::FONT_HERSHEY_SIMPLEX, 0.35,
                cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
  }
  for (int k = 0; k <= 5; ++k) {
    const double x = x0 + (x1 - x0) * k / 5.0;
    std::snprintf(buf, sizeof(buf), "%.1f", x);
    cv::putText(img, buf, P(x, y0) + cv::Point2d(-10, 14), cv::FONT_HERSHEY_SIMPLEX, 0.35,
                cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
  }
  cv::putText(img, spec.title, cv::Point(left, 17), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, spec.x_label + "   (y: " + spec.y_label + ")", cv::Point(left, h - 20),
              cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
  int lx = left;
  for (const Series& s : spec.series) {
    const cv::Scalar c = CssToBgr(s.color);
    std::vector<cv::Point> line;
    const auto flush = [&] {
      if (line.size() >= 2) cv::polylines(img, line, false, c, 1, cv::LINE_AA);
      line.clear();
    };
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        flush();
        continue;
      }
      const cv::Point p = P(s.x[i], s.y[i]);
      if (s.points)
        cv::circle(img, p, 1, c, cv::FILLED);
      else
        line.push_back(p);
    }
    flush();
    if (s.label.empty()) continue;
    cv::line(img, cv::Point(lx, h - 6), cv::Point(lx + 18, h - 6), c, 3);
    cv::putText(img, s.label, cv::Point(lx + 22, h - 2), cv::FONT_HERSHEY_SIMPLEX, 0.38,
                cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
    lx += 34 + 7 * static_cast<int>(s.label.size());
  }
  return img;
}

}  // namespace mapless::report

// Checks a screenshot of the demo's report: the plots are drawn, not a blank or broken page.
// Counts the pixels of the report's path colours (taught red #d62728, repeated green #2ca02c,
// the v series blue #1f77b4) and the non-white pixels.
//   screenshot_check SCREENSHOT.png      exit 0 when each colour has at least 300 pixels
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace {

int Near(const cv::Mat& bgr, cv::Scalar colour) {
  cv::Mat mask;
  cv::inRange(bgr, colour - cv::Scalar(30, 30, 30), colour + cv::Scalar(30, 30, 30), mask);
  return cv::countNonZero(mask);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: screenshot_check SCREENSHOT.png\n");
    return 2;
  }
  const cv::Mat img = cv::imread(argv[1], cv::IMREAD_COLOR);
  if (img.empty()) {
    std::fprintf(stderr, "screenshot_check: %s: not a readable image\n", argv[1]);
    return 1;
  }
  cv::Mat grey;
  cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
  const double ink = 1.0 - static_cast<double>(cv::countNonZero(grey > 245)) / grey.total();
  const int red = Near(img, cv::Scalar(40, 39, 214));
  const int green = Near(img, cv::Scalar(44, 160, 44));
  const int blue = Near(img, cv::Scalar(180, 119, 31));
  std::printf(
      "screenshot %dx%d: %.0f%% not white; taught red %d px, repeated green %d px, "
      "v blue %d px\n",
      img.cols, img.rows, 100.0 * ink, red, green, blue);
  return ink > 0.1 && red >= 300 && green >= 300 && blue >= 300 ? 0 : 1;
}

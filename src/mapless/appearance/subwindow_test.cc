#include "mapless/appearance/subwindow.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mapless/appearance/image.h"

namespace mapless::appearance {
namespace {

TEST(SubWindows, AnAlignedViewMatchesTheQueryWindowsThemselves) {
  cv::Mat image(64, 64, CV_32F);
  cv::randu(image, -1.0, 1.0);
  const SubWindowOptions options;
  const SubWindowEigenspace route = BuildSubWindowEigenspace(image, options);
  EXPECT_EQ(route.windows(), 49);
  const auto matches = MatchSubWindows(route, image, options);
  ASSERT_EQ(matches.size(), 7U);
  const auto query = QueryWindowIndices(route.windows());
  int exact = 0;
  for (const SubWindowMatch& m : matches)
    exact += m.stored == query[static_cast<std::size_t>(m.query)];
  EXPECT_EQ(exact, 5);  // every query window finds itself; two more are neighbours
}

TEST(SubWindows, AShiftedViewMatchesShiftedWindows) {
  cv::Mat wide(64, 80, CV_32F);
  cv::randu(wide, -1.0, 1.0);
  cv::GaussianBlur(wide, wide, cv::Size(5, 5), 1.0);
  const cv::Mat route_image = wide.colRange(8, 72).clone();
  const cv::Mat current = wide.colRange(4, 68).clone();  // content 4 px further right now
  const SubWindowOptions options;
  const SubWindowEigenspace route = BuildSubWindowEigenspace(route_image, options);
  const auto query = QueryWindowIndices(route.windows());
  int shifted = 0;
  for (const SubWindowMatch& m : MatchSubWindows(route, current, options)) {
    shifted += m.stored == query[static_cast<std::size_t>(m.query)] - 4;
  }
  EXPECT_GE(shifted, 3);  // the windows that stay inside the route image
}

}  // namespace
}  // namespace mapless::appearance

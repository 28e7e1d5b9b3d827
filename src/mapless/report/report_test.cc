// The report's pieces (svg.h, html.h, pictures.h): well-formed, escaped, self-contained.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "mapless/io/lazy_libraries.h"
#include "mapless/report/html.h"
#include "mapless/report/pictures.h"
#include "mapless/report/svg.h"

namespace mapless::report {
namespace {

int Count(const std::string& s, const std::string& what) {
  int n = 0;
  for (auto at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

std::vector<unsigned char> FromBase64(const std::string& text) {
  const std::string table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  unsigned v = 0;
  int bits = 0;
  for (char c : text) {
    if (c == '=') break;
    v = (v << 6) | static_cast<unsigned>(table.find(c));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((v >> bits) & 0xff));
    }
  }
  return out;
}

TEST(Report, EscapesText) {
  EXPECT_EQ(Escape("a<b & \"c\" 'd'>"), "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;");
}

TEST(Report, LinePlotHasOnePathPerSeriesAndBreaksAtGaps) {
  PlotSpec spec;
  spec.title = "commands <v>";
  spec.series.push_back({{0, 1, 2, 3}, {0.0, 0.1, std::nan(""), 0.2}, "#ff0000", "v", false});
  spec.series.push_back({{0, 1}, {1, 2}, "#0000ff", "omega", true});
  const std::string svg = LinePlotSvg(spec);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(Count(svg, "<path "), 2);
  EXPECT_EQ(Count(svg, "stroke-dasharray"), 2);  // the dashed series and its legend
  EXPECT_NE(svg.find("commands &lt;v&gt;"), std::string::npos);
  // The gap starts a new sub-path: M ... L ... M.
  const auto d = svg.find("d=\"M");
  ASSERT_NE(d, std::string::npos);
  EXPECT_EQ(Count(svg.substr(d, svg.find('"', d + 3) - d), "M"), 2);
  EXPECT_NE(LinePlotSvg(PlotSpec{}).find("no data"), std::string::npos);
}

TEST(Report, TopDownDrawsTheWorldAndEveryPath) {
  sim::World world;
  sim::WorldObject wall;
  wall.kind = sim::ObjectKind::kWall;
  wall.a = {0, -1};
  wall.b = {5, -1};
  sim::WorldObject box;
  box.kind = sim::ObjectKind::kBox;
  box.center = {2, 1};
  box.size_m = {0.5, 0.5};
  world.objects = {wall, box};
  PathSpec taught{{{0, 0, 0}, {4, 0, 0}}, "#d62728", "taught"};
  PathSpec repeated{{{0, 0.1, 0}, {4, 0.05, 0}}, "#2ca02c", "repeated"};
  const std::string svg = TopDownSvg(world, {taught, repeated}, {{4, 0}});
  EXPECT_EQ(Count(svg, "<polyline"), 2);
  EXPECT_EQ(Count(svg, "<polygon"), 1);
  EXPECT_NE(svg.find("&#9733;"), std::string::npos);
  EXPECT_NE(svg.find(">taught<"), std::string::npos);
}

TEST(Report, HtmlIsSelfContainedAndImagesDecode) {
  HtmlReport report("run <1>");
  report.Heading("Results");
  report.Table({"scenario", "successes"}, {{"a&b", "10/10"}});
  report.Figure(LinePlotSvg(PlotSpec{}), "empty");
  cv::Mat img(20, 30, CV_8UC3, cv::Scalar(10, 200, 30));
  report.Images({{img, "an image"}});
  const std::string html = report.Html();
  EXPECT_NE(html.find("<title>run &lt;1&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("<td>a&amp;b</td><td class=\"n\">10/10</td>"), std::string::npos);
  // Nothing outside the file: no scripts, no links but the SVG namespace.
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(Count(html, "http"), Count(html, "http://www.w3.org/2000/svg"));
  const std::string prefix = "src=\"data:image/png;base64,";
  const auto at = html.find(prefix);
  ASSERT_NE(at, std::string::npos);
  const auto start = at + prefix.size();
  const cv::Mat back = io::lazy::ImDecode(
      cv::Mat(FromBase64(html.substr(start, html.find('"', start) - start))), cv::IMREAD_COLOR);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(cv::norm(back, img, cv::NORM_INF), 0.0);
}

TEST(Report, PicturesHaveTheirSizes) {
  cv::Mat cur(60, 80, CV_8UC1, cv::Scalar(100));
  cv::Mat thumb(30, 40, CV_8UC1, cv::Scalar(150));
  EXPECT_EQ(MatchPicture(cur, thumb, {{10, 10}}, {{12, 11}}, "slopes").size(), cv::Size(160, 60));
  cv::Mat mask(15, 20, CV_8UC1, cv::Scalar(0));
  mask.rowRange(8, 15).setTo(255);
  const cv::Mat plane = PlanePicture(cur, mask, 0.3, "");
  EXPECT_EQ(plane.size(), cur.size());
  // The bottom is plane (green tint), the top obstacle (red tint).
  EXPECT_GT(plane.at<cv::Vec3b>(55, 5)[1], plane.at<cv::Vec3b>(55, 5)[2]);
  EXPECT_GT(plane.at<cv::Vec3b>(5, 70)[2], plane.at<cv::Vec3b>(5, 70)[1]);
  const cv::Mat belief = BeliefPicture({{0.1F, 0.9F}, {0.2F, 0.5F, 0.3F}}, {1, 1}, 100);
  EXPECT_EQ(belief.rows, 100);
  PlotSpec spec;
  spec.series.push_back({{0, 1}, {0, 1}, "#ff0000", "x", false});
  const cv::Mat plot = LinePlotPicture(spec);
  EXPECT_EQ(plot.size(), cv::Size(spec.width_px, spec.height_px));
  EXPECT_GT(cv::countNonZero(plot.reshape(1) == 255), 0);
}

}  // namespace
}  // namespace mapless::report

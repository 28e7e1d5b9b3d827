#include "mapless/sim/renderer.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <set>

#include "mapless/sim/simulation.h"

namespace mapless::sim {
namespace {

TextureSpec Flat(double mean) {
  TextureSpec t;
  t.type = TextureType::kPlain;
  t.contrast = 0.0;
  t.mean = mean;
  return t;
}

// A dark wall at x = 6 with small bright squares (posters) at known 3D points.
World MarkerWorld(const std::vector<Eigen::Vector3d>& markers) {
  World w;
  w.ground = Flat(60);
  w.sky_top = w.sky_horizon = 60;
  WorldObject wall;
  wall.kind = ObjectKind::kWall;
  wall.a = Eigen::Vector2d(6.0, 10.0);
  wall.b = Eigen::Vector2d(6.0, -10.0);
  wall.height_m = 5.0;
  wall.texture = Flat(20);
  w.objects.push_back(wall);
  for (const auto& m : markers) {
    WorldObject p;
    p.kind = ObjectKind::kPoster;
    p.center = m.head<2>();
    p.z_m = m.z();
    p.size_m = Eigen::Vector2d(0.06, 0.06);
    p.yaw_rad = kPi;  // faces the camera at the origin
    p.texture = Flat(250);
    w.objects.push_back(p);
  }
  return w;
}

std::vector<cv::Point2d> BrightBlobCentroids(const cv::Mat& image) {
  cv::Mat mask;
  cv::threshold(image, mask, 120, 255, cv::THRESH_BINARY);
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids);
  std::vector<cv::Point2d> out;
  for (int i = 1; i < n; ++i) {
    // Intensity-weighted centroid over the blob's bounding box grown by 2 px (edge pixels are
    // grey).
    const cv::Rect box(stats.at<int>(i, 0) - 2, stats.at<int>(i, 1) - 2, stats.at<int>(i, 2) + 4,
                       stats.at<int>(i, 3) + 4);
    double sum = 0, sx = 0, sy = 0;
    for (int y = box.y; y < box.y + box.height; ++y) {
      for (int x = box.x; x < box.x + box.width; ++x) {
        const double v = std::max(0.0, image.at<std::uint8_t>(y, x) - 20.0);
        sum += v;
        sx += v * x;
        sy += v * y;
      }
    }
    out.emplace_back(sx / sum, sy / sum);
  }
  return out;
}

void ExpectMarkersAtProjections(const CameraMount& mount, const Pose2& robot) {
  const std::vector<Eigen::Vector3d> markers = {
      {5.98, 0.0, 0.4}, {5.98, 1.5, 1.0}, {5.98, -2.0, 0.2}, {5.98, 0.7, 1.8}, {5.98, -1.1, 1.3}};
  const World world = MarkerWorld(markers);
  const Renderer renderer(world, RenderOptions{});
  const CameraModel cam = CameraModel::FromFov(320, 240, DegToRad(60));
  const Rigid3 world_from_camera = WorldFromCamera(robot, mount);
  const cv::Mat image = renderer.Render(cam, world_from_camera);
  const auto found = BrightBlobCentroids(image);
  int checked = 0;
  for (const auto& m : markers) {
    const auto uv = cam.Project(world_from_camera.inverse() * m);
    if (!uv || uv->x() < 5 || uv->y() < 5 || uv->x() > 314 || uv->y() > 234) continue;
    double best = 1e9;
    for (const auto& f : found) best = std::min(best, std::hypot(f.x - uv->x(), f.y - uv->y()));
    EXPECT_LT(best, 1.0) << "marker (" << m.transpose() << ") projected at " << uv->transpose();
    ++checked;
  }
  EXPECT_GE(checked, 3);
}

TEST(Renderer, KnownWorldPointsAppearWhereTheCameraModelProjectsThem) {
  ExpectMarkersAtProjections(CameraMount{}, Pose2{0, 0, 0});
}

TEST(Renderer, ProjectionHoldsForPitchedAndOffsetCameraOnATurnedRobot) {
  CameraMount mount;
  mount.height_m = 0.9;
  mount.pitch_rad = DegToRad(12);
  mount.forward_m = 0.15;
  ExpectMarkersAtProjections(mount, Pose2{0.4, -0.3, DegToRad(8)});
}

TEST(Renderer, GroundBelowAndSkyAboveTheHorizonForALevelCamera) {
  World w;
  w.ground = Flat(40);
  w.sky_top = w.sky_horizon = 220;
  const Renderer renderer(w, RenderOptions{});
  const CameraModel cam = CameraModel::FromFov(320, 240, DegToRad(60));
  const cv::Mat img = renderer.Render(cam, WorldFromCamera(Pose2{}, CameraMount{}));
  EXPECT_NEAR(img.at<std::uint8_t>(20, 160), 220, 1);
  EXPECT_NEAR(img.at<std::uint8_t>(230, 160), 40, 1);
  // A level camera sees the horizon at the principal point's row (119.5).
  EXPECT_GT(img.at<std::uint8_t>(117, 160), 150);
  EXPECT_LT(img.at<std::uint8_t>(122, 160), 150);
}

TEST(Renderer, SilhouetteEdgesAreAntiAliasedAndMoveSmoothlyWithSubPixelMotion) {
  // A bright wall ending at y = 0 in front of a dark background: slide the camera sideways by
  // tiny steps and follow the grey level of the pixel on the edge.
  World w;
  w.ground = Flat(30);
  w.sky_top = w.sky_horizon = 30;
  WorldObject wall;
  wall.kind = ObjectKind::kWall;
  wall.a = Eigen::Vector2d(4.0, 0.0);
  wall.b = Eigen::Vector2d(4.0, -5.0);
  wall.height_m = 5.0;
  wall.texture = Flat(230);
  w.objects.push_back(wall);
  const Renderer renderer(w, RenderOptions{});
  const CameraModel cam = CameraModel::FromFov(320, 240, DegToRad(60));
  // The edge (world y = 0) appears at image x = cx + k for a camera at y = k pixels' worth of
  // metres; pixel 160 spans [cx, cx + 1]. Sweep k across that pixel in eighths of a pixel: the
  // wall covers a fraction 1 - k of the pixel.
  const double px_m = 4.0 / cam.fx;
  std::vector<int> values;
  for (int i = 0; i < 8; ++i) {
    const double k = 0.0625 + 0.125 * i;
    const cv::Mat img =
        renderer.Render(cam, WorldFromCamera(Pose2{0.0, k * px_m, 0.0}, CameraMount{}));
    values.push_back(img.at<std::uint8_t>(100, 160));
  }
  // Less and less of the wall: never brighter, from nearly all wall to nearly all sky...
  for (std::size_t i = 1; i < values.size(); ++i) EXPECT_LE(values[i], values[i - 1]) << i;
  EXPECT_GT(values.front(), 150);
  EXPECT_LT(values.back(), 60);
  // ...through intermediate grey levels (an aliased renderer would jump from wall to sky at once).
  std::set<int> interior;
  for (int v : values) {
    if (v > 45 && v < 170) interior.insert(v);
  }
  EXPECT_GE(interior.size(), 3u);
}

TEST(Renderer, SameSceneAndPoseGiveIdenticalBytes) {
  const Scenario s = LoadScenario("narrow_room_sharp_turn");
  Simulation a(s.world, s.camera, {}, 5);
  Simulation b(s.world, s.camera, {}, 5);
  a.AddRobot(Pose2{1.0, 0.1, 0.2}, s.robot);
  b.AddRobot(Pose2{1.0, 0.1, 0.2}, s.robot);
  const cv::Mat ia = a.Render(0);
  const cv::Mat ib = b.Render(0);
  ASSERT_EQ(ia.size(), ib.size());
  EXPECT_EQ(cv::norm(ia, ib, cv::NORM_INF), 0.0);
}

TEST(Renderer, ImageNoiseIsDeterministicPerSeedAndDiffersAcrossSeeds) {
  Scenario s = LoadScenario("narrow_room_sharp_turn");
  s.camera.effects.noise_sigma = 8.0;
  s.camera.effects.invert_fraction = 0.2;
  Simulation a(s.world, s.camera, {}, 5);
  Simulation b(s.world, s.camera, {}, 5);
  Simulation c(s.world, s.camera, {}, 6);
  for (Simulation* sim : {&a, &b, &c}) sim->AddRobot(Pose2{1.0, 0.1, 0.2}, s.robot);
  const cv::Mat ia = a.Render(0);
  EXPECT_EQ(cv::norm(ia, b.Render(0), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(ia, c.Render(0), cv::NORM_L1), 0.0);
  // About 20% of the pixels are inverted.
  cv::Mat diff;
  cv::absdiff(ia, a.RenderClean(0), diff);
  const double changed = cv::countNonZero(diff > 40) / static_cast<double>(diff.total());
  EXPECT_GT(changed, 0.12);
  EXPECT_LT(changed, 0.25);
}

}  // namespace
}  // namespace mapless::sim

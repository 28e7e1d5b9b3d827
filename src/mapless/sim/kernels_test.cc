// The renderer's kernels (raster.h): the shading pass gives ShadeHit's bytes pixel for pixel, and
// the AVX2 build of every kernel gives the baseline's bytes.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "mapless/core/testing.h"
#include "mapless/sim/raster.h"
#include "mapless/sim/renderer.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::sim::raster {
namespace {

using mapless::testing::SameBytes;

// Pass 1 of one view, as Renderer::Render runs it (baseline kernel).
struct View {
  CameraModel cam;
  std::vector<Prepared> prepared;
  std::vector<float> xd, yd;
  Buffers buf;
  SkyRamp sky;
  float lod_slope = 0.0f;
};

View PassOne(const Renderer& renderer, const World& world, const CameraModel& cam,
             const Rigid3& world_from_camera) {
  const RenderOptions options;
  View v;
  v.cam = cam;
  v.prepared = PrepareSurfaces(renderer.surfaces(), {}, cam, world_from_camera.inverse(), options);
  for (int x = 0; x < cam.width; ++x) v.xd.push_back(static_cast<float>((x - cam.cx) / cam.fx));
  for (int y = 0; y < cam.height; ++y) v.yd.push_back(static_cast<float>((y - cam.cy) / cam.fy));
  const std::size_t npix =
      static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  v.buf.depth.assign(npix, std::numeric_limits<float>::infinity());
  v.buf.id.assign(npix, -1);
  v.buf.alpha.assign(npix, 0.0f);
  v.buf.beta.assign(npix, 0.0f);
  v.buf.nd.assign(npix, 0.0f);
  baseline::RasterNearest(v.prepared, v.xd, v.yd, cam.width, static_cast<float>(options.near_m),
                          static_cast<float>(options.far_m), &v.buf);
  v.sky = SkyRamp{world.sky_top, world.sky_horizon, v.yd.front(), v.yd.back()};
  v.lod_slope = static_cast<float>(0.5 * (3.0 + options.anisotropy));
  return v;
}

// The shading pass written the plain way: ShadeHit per pixel, saturate_cast to a byte.
cv::Mat ShadeHitImage(const View& v) {
  cv::Mat image(v.cam.height, v.cam.width, CV_8UC1);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.cols) +
                            static_cast<std::size_t>(x);
      const std::int32_t id = v.buf.id[i];
      const float value =
          id < 0 ? v.sky(v.yd[static_cast<std::size_t>(y)])
                 : ShadeHit(v.prepared[static_cast<std::size_t>(id)],
                            Hit{v.buf.depth[i], v.buf.alpha[i], v.buf.beta[i], v.buf.nd[i]},
                            v.lod_slope);
      image.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(value);
    }
  }
  return image;
}

bool CpuRunsAvx2() {
  UseBaselineRenderKernels(false);
  return std::string(RenderKernels()) == "avx2";
}

// The kernel builds this machine runs: the baseline always, AVX2 where the CPU has it.
std::vector<KernelSet> RunnableKernels() {
  std::vector<KernelSet> sets;
  UseBaselineRenderKernels(true);
  sets.push_back(Kernels());
  if (CpuRunsAvx2()) sets.push_back(Kernels());
  UseBaselineRenderKernels(false);
  return sets;
}

// Indoor with a ceiling and posters, a cylinder (facets of one group, a disk), parked cars.
const char* const kScenarios[] = {"narrow_room_sharp_turn", "obstacle_cylinder_outdoor",
                                  "lifelong_car_park"};

TEST(RendererKernels, ShadingGivesShadeHitsBytesPixelForPixel) {
  int views = 0;
  for (const char* name : kScenarios) {
    const Scenario scenario = LoadScenario(name);
    const Renderer renderer(scenario.world, RenderOptions{});
    for (const Pose2& pose : PosesAlongTaughtPath(scenario, 2)) {
      const View v = PassOne(renderer, scenario.world, scenario.camera.model,
                             WorldFromCamera(pose, scenario.camera.mount));
      const cv::Mat expected = ShadeHitImage(v);
      for (const KernelSet& k : RunnableKernels()) {
        cv::Mat image(v.cam.height, v.cam.width, CV_8UC1);
        k.shade_image(v.prepared, v.buf, v.yd, v.sky, v.lod_slope, &image);
        EXPECT_TRUE(SameBytes(image, expected)) << name << ", " << k.name << " kernels";
      }
      ++views;
    }
  }
  EXPECT_EQ(views, 6);
}

// Texels of 10 um seen 1 km from the world's origin: the texture coordinates in 24.8 fixed point
// pass 2^31, where the shading pass hands the run to ShadeHit's 64-bit arithmetic.
TEST(RendererKernels, ShadingBeyond32BitTextureCoordinatesIsShadeHits) {
  World world;
  world.ground.type = TextureType::kNoise;
  world.ground.texel_m = 1e-5;
  world.ground.size_px = 64;
  const Renderer renderer(world, RenderOptions{});
  const CameraModel cam = CameraModel::FromFov(160, 120, DegToRad(60));
  CameraMount mount;
  mount.height_m = 1.0;
  const View v = PassOne(renderer, world, cam, WorldFromCamera(Pose2{1000.0, 0.0, 0.0}, mount));
  int beyond = 0;
  for (std::size_t i = 0; i < v.buf.id.size(); ++i) {
    if (v.buf.id[i] < 0) continue;
    const Prepared& p = v.prepared[static_cast<std::size_t>(v.buf.id[i])];
    beyond += std::abs(v.buf.alpha[i] * p.s_scale * 256.0f) >= 2147483648.0f;
  }
  EXPECT_GT(beyond, 100) << "the view must reach the case it tests";
  const cv::Mat expected = ShadeHitImage(v);
  for (const KernelSet& k : RunnableKernels()) {
    cv::Mat image(cam.height, cam.width, CV_8UC1);
    k.shade_image(v.prepared, v.buf, v.yd, v.sky, v.lod_slope, &image);
    EXPECT_TRUE(SameBytes(image, expected)) << k.name << " kernels";
  }
}

TEST(RendererKernels, Avx2KernelsGiveTheBaselineBytes) {
  if (!CpuRunsAvx2()) GTEST_SKIP() << "this CPU does not run AVX2: only the baseline kernels run";
  int views = 0;
  for (const char* name : kScenarios) {
    const Scenario scenario = LoadScenario(name);
    // The default supersampling everywhere, the most on the first scenario.
    for (const int supersample : {4, 8}) {
      if (supersample != 4 && name != kScenarios[0]) continue;
      RenderOptions options;
      options.edge_supersample = supersample;
      const Renderer renderer(scenario.world, options);
      for (const Pose2& pose : PosesAlongTaughtPath(scenario, 2)) {
        // Another robot's box in front of the camera: the extra surfaces go through the kernels.
        WorldObject box;
        box.kind = ObjectKind::kBox;
        box.center = Eigen::Vector2d(pose.x_m + 1.5 * std::cos(pose.theta_rad),
                                     pose.y_m + 1.5 * std::sin(pose.theta_rad));
        box.size_m = Eigen::Vector2d(0.4, 0.3);
        box.height_m = 0.5;
        box.yaw_rad = 0.3;
        std::vector<Surface> extra;
        AppendObjectSurfaces(box, renderer.surfaces().front().texture, &extra,
                             LightDirection(scenario.world));
        std::vector<CameraModel> cameras = {scenario.camera.model};
        if (views == 0) cameras.push_back(CameraModel::FromFov(640, 480, DegToRad(70)));
        for (const CameraModel& cam : cameras) {
          const Rigid3 pose3 = WorldFromCamera(pose, scenario.camera.mount);
          UseBaselineRenderKernels(true);
          const cv::Mat baseline = renderer.Render(cam, pose3, extra);
          UseBaselineRenderKernels(false);
          const cv::Mat avx2 = renderer.Render(cam, pose3, extra);
          EXPECT_TRUE(SameBytes(avx2, baseline))
              << name << ", supersample " << supersample << ", " << cam.width << "x" << cam.height;
          ++views;
        }
      }
    }
  }
  EXPECT_EQ(views, (3 + 1) * 2 + 1);
}

}  // namespace
}  // namespace mapless::sim::raster

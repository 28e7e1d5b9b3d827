#include "mapless/sim/renderer.h"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>

#include "mapless/core/check.h"
#include "mapless/core/cpu.h"
#include "mapless/sim/raster.h"

namespace mapless::sim {
namespace {

const Eigen::Vector3d kLightDir = Eigen::Vector3d(0.35, 0.55, 0.76).normalized();

float ShadeFor(const Eigen::Vector3d& normal, const Eigen::Vector3d& light) {
  return static_cast<float>(0.6 + 0.4 * std::abs(normal.normalized().dot(light)));
}

std::atomic<bool> force_baseline_kernels{false};

}  // namespace

namespace raster {

const KernelSet& Kernels() {
  static const KernelSet kBaseline{"baseline", baseline::RasterNearest, baseline::ShadeImage,
                                   baseline::SupersampleEdges};
#if defined(__x86_64__) || defined(__i386__)
  static const KernelSet kAvx2{"avx2", avx2::RasterNearest, avx2::ShadeImage,
                               avx2::SupersampleEdges};
  if (CpuHasAvx2() && !force_baseline_kernels.load(std::memory_order_relaxed)) return kAvx2;
#endif
  return kBaseline;
}

}  // namespace raster

const char* RenderKernels() { return raster::Kernels().name; }

void UseBaselineRenderKernels(bool baseline) {
  force_baseline_kernels.store(baseline, std::memory_order_relaxed);
}

void RenderOptions::Validate() const {
  MAPLESS_CHECK(edge_supersample >= 1 && edge_supersample <= 8,
                "RenderOptions.edge_supersample = " << edge_supersample << "; must be in [1, 8]");
  MAPLESS_CHECK(near_m > 0.0, "RenderOptions.near_m = " << near_m << "; must be > 0");
  MAPLESS_CHECK(far_m > near_m, "RenderOptions.far_m = " << far_m << "; must be > near_m");
  MAPLESS_CHECK(anisotropy >= 0.0 && anisotropy <= 1.0,
                "RenderOptions.anisotropy = " << anisotropy << "; must be in [0, 1]");
}

Eigen::Vector3d LightDirection(const World& world) {
  if (!world.light_azimuth_deg) return kLightDir;
  const double a = DegToRad(*world.light_azimuth_deg);
  const double horizontal = std::hypot(kLightDir.x(), kLightDir.y());
  return Eigen::Vector3d(horizontal * std::cos(a), horizontal * std::sin(a), kLightDir.z());
}

void AppendObjectSurfaces(const WorldObject& o, std::shared_ptr<const Texture> texture,
                          std::vector<Surface>* out, const Eigen::Vector3d& light) {
  auto add = [&](Surface::Shape shape, const Eigen::Vector3d& origin, const Eigen::Vector3d& e1,
                 const Eigen::Vector3d& e2, bool one_sided) {
    Surface s;
    s.shape = shape;
    s.origin = origin;
    s.e1 = e1;
    s.e2 = e2;
    s.one_sided = one_sided;
    s.shade = ShadeFor(e1.cross(e2), light);
    s.texture = texture;
    out->push_back(s);
  };
  const Eigen::Vector3d up(0, 0, 1);
  switch (o.kind) {
    case ObjectKind::kWall: {
      const Eigen::Vector3d a(o.a.x(), o.a.y(), 0.0);
      const Eigen::Vector3d b(o.b.x(), o.b.y(), 0.0);
      add(Surface::Shape::kParallelogram, a, b - a, up * o.height_m, false);
      break;
    }
    case ObjectKind::kBox: {
      const double c = std::cos(o.yaw_rad);
      const double s = std::sin(o.yaw_rad);
      const Eigen::Vector3d ex(c * o.size_m.x(), s * o.size_m.x(), 0.0);
      const Eigen::Vector3d ey(-s * o.size_m.y(), c * o.size_m.y(), 0.0);
      const Eigen::Vector3d h = up * o.height_m;
      const Eigen::Vector3d base =
          Eigen::Vector3d(o.center.x(), o.center.y(), 0.0) - 0.5 * ex - 0.5 * ey;
      // Four sides, outward normals (e1 x e2 points out), and the top.
      add(Surface::Shape::kParallelogram, base, ex, h, true);
      add(Surface::Shape::kParallelogram, base + ex, ey, h, true);
      add(Surface::Shape::kParallelogram, base + ex + ey, -ex, h, true);
      add(Surface::Shape::kParallelogram, base + ey, -ey, h, true);
      add(Surface::Shape::kParallelogram, base + h, ex, ey, true);
      break;
    }
    case ObjectKind::kCylinder: {
      const int facets = 20;
      const int group = static_cast<int>(out->size());  // unique among this list's surfaces
      const double step = 2.0 * kPi / facets;
      const Eigen::Vector3d h = up * o.height_m;
      for (int i = 0; i < facets; ++i) {
        const double a0 = i * step;
        const double a1 = (i + 1) * step;
        const Eigen::Vector3d p0(o.center.x() + o.radius_m * std::cos(a0),
                                 o.center.y() + o.radius_m * std::sin(a0), 0.0);
        const Eigen::Vector3d p1(o.center.x() + o.radius_m * std::cos(a1),
                                 o.center.y() + o.radius_m * std::sin(a1), 0.0);
        add(Surface::Shape::kParallelogram, p0, p1 - p0, h, true);
        out->back().edge_group = group;
      }
      add(Surface::Shape::kDisk, Eigen::Vector3d(o.center.x(), o.center.y(), o.height_m),
          Eigen::Vector3d(o.radius_m, 0, 0), Eigen::Vector3d(0, o.radius_m, 0), true);
      break;
    }
    case ObjectKind::kPoster: {
      // Seen from the direction yaw_rad points to; e1 runs to the viewer's right.
      const Eigen::Vector3d facing(std::cos(o.yaw_rad), std::sin(o.yaw_rad), 0.0);
      const Eigen::Vector3d right = up.cross(facing) * -1.0;  // viewer's right when facing it
      const Eigen::Vector3d e1 = right * o.size_m.x();
      const Eigen::Vector3d e2 = -up * o.size_m.y();  // top to bottom, like the image
      const Eigen::Vector3d centre(o.center.x(), o.center.y(), o.z_m);
      add(Surface::Shape::kParallelogram, centre - 0.5 * e1 - 0.5 * e2, e1, e2, false);
      break;
    }
  }
}

Renderer::Renderer(const World& world, RenderOptions options) : options_(options) {
  options_.Validate();
  world.Validate();
  sky_top_ = world.sky_top;
  sky_horizon_ = world.sky_horizon;
  // Objects with identical texture specs share one texture (repeating doors and posters).
  std::map<TextureKey, std::shared_ptr<const Texture>> cache;
  auto texture_for = [&](const TextureSpec& spec) {
    const TextureKey key = TextureKeyOf(spec);
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, GenerateTexture(spec)).first;
    return it->second;
  };
  const Eigen::Vector3d light = LightDirection(world);
  for (const WorldObject& o : world.objects)
    AppendObjectSurfaces(o, texture_for(o.texture), &surfaces_, light);
  Surface ground;
  ground.shape = Surface::Shape::kPlane;
  ground.origin = Eigen::Vector3d::Zero();
  ground.e1 = Eigen::Vector3d::UnitX();
  ground.e2 = Eigen::Vector3d::UnitY();
  ground.texture = texture_for(world.ground);
  surfaces_.push_back(ground);
  if (world.ceiling) {
    Surface ceiling = ground;
    ceiling.origin = Eigen::Vector3d(0, 0, world.ceiling_height_m);
    ceiling.shade = 0.85f;
    ceiling.texture = texture_for(*world.ceiling);
    surfaces_.push_back(ceiling);
  }
}

cv::Mat Renderer::Render(const CameraModel& cam, const Rigid3& world_from_camera,
                         const std::vector<Surface>& extra) const {
  cam.Validate();
  const Rigid3 camera_from_world = world_from_camera.inverse();
  const int w = cam.width;
  const int h = cam.height;
  const float near_m = static_cast<float>(options_.near_m);
  const float far_m = static_cast<float>(options_.far_m);
  const float lod_slope = static_cast<float>(0.5 * (3.0 + options_.anisotropy));
  const std::vector<raster::Prepared> prepared =
      raster::PrepareSurfaces(surfaces_, extra, cam, camera_from_world, options_);
  std::vector<float> xd(static_cast<std::size_t>(w));
  std::vector<float> yd(static_cast<std::size_t>(h));
  for (int x = 0; x < w; ++x)
    xd[static_cast<std::size_t>(x)] = static_cast<float>((x - cam.cx) / cam.fx);
  for (int y = 0; y < h; ++y)
    yd[static_cast<std::size_t>(y)] = static_cast<float>((y - cam.cy) / cam.fy);

  const std::size_t npix = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  // Per thread, kept from one render to the next: a frame's buffers are megabytes, and allocating
  // them anew for every frame costs page faults (most of all under AddressSanitizer, which maps
  // every large block afresh). alpha, beta and nd are read only where id says a surface was hit,
  // where pass 1 wrote them.
  thread_local raster::Buffers buf;
  buf.depth.assign(npix, std::numeric_limits<float>::infinity());
  buf.id.assign(npix, -1);
  buf.alpha.resize(npix);
  buf.beta.resize(npix);
  buf.nd.resize(npix);

  const raster::KernelSet& kernels = raster::Kernels();
  kernels.raster_nearest(prepared, xd, yd, w, near_m, far_m, &buf);
  const raster::SkyRamp sky{sky_top_, sky_horizon_, yd.front(), yd.back()};

  cv::Mat image(h, w, CV_8UC1);
  kernels.shade_image(prepared, buf, yd, sky, lod_slope, &image);

  // Pass 2: supersample silhouette pixels, where the visible surface differs from a neighbour.
  const int ss = options_.edge_supersample;
  if (ss > 1)
    kernels.supersample_edges(prepared, buf, xd, yd, cam, ss, near_m, far_m, lod_slope, sky,
                              &image);
  return image;
}

}  // namespace mapless::sim

#include "mapless/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <tuple>

#include "mapless/core/check.h"

namespace mapless::sim {
namespace {

const Eigen::Vector3d kLightDir = Eigen::Vector3d(0.35, 0.55, 0.76).normalized();

float ShadeFor(const Eigen::Vector3d& normal) {
  return static_cast<float>(0.6 + 0.4 * std::abs(normal.normalized().dot(kLightDir)));
}

// log2 approximation (max error ~0.01) for mip selection.
inline float FastLog2(float x) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &x, sizeof(bits));
  const float exponent = static_cast<float>(static_cast<int>((bits >> 23) & 0xFF) - 127);
  bits = (bits & 0x007FFFFF) | 0x3F800000;  // mantissa m in [1, 2)
  float m = 0.0f;
  std::memcpy(&m, &bits, sizeof(m));
  return exponent + (-0.34484843f * m + 2.02466578f) * m - 0.67487759f;
}

// A surface prepared for one camera: everything in the camera frame, as coefficients of the ray
// direction d = (xd, yd, 1) through a pixel.
struct Prepared {
  Surface::Shape shape;
  // Plane n . P = k (n unit).
  float nx, ny, nz, k;
  // alpha = t * (a1 . d) - c1, beta = t * (a2 . d) - c2 (surface coordinates, 0..1 on the
  // parallelogram, unit disk for disks, metres/texel-scaled for planes).
  float a1x, a1y, a1z, c1;
  float a2x, a2y, a2z, c2;
  float s_scale, t_scale;  // texels per unit of alpha, beta (level 0)
  float lod_scale;         // log2 factor: area_texels = t^2 * lod_scale / |n . d|
  float shade;
  const Texture* texture;
  int x0, x1, y0, y1;      // inclusive screen bounds
};

struct Hit {
  float t;
  float alpha;
  float beta;
  float nd;
};

// Ray d = (xd, yd, 1): intersection with the prepared surface, or false.
inline bool Intersect(const Prepared& p, float xd, float yd, float near_m, float far_m, Hit* hit) {
  const float nd = p.nx * xd + p.ny * yd + p.nz;
  if (nd == 0.0f) return false;
  const float t = p.k / nd;
  if (!(t > near_m && t < far_m)) return false;
  const float alpha = t * (p.a1x * xd + p.a1y * yd + p.a1z) - p.c1;
  const float beta = t * (p.a2x * xd + p.a2y * yd + p.a2z) - p.c2;
  switch (p.shape) {
    case Surface::Shape::kParallelogram:
      if (alpha < 0.0f || alpha > 1.0f || beta < 0.0f || beta > 1.0f) return false;
      break;
    case Surface::Shape::kDisk:
      if (alpha * alpha + beta * beta > 1.0f) return false;
      break;
    case Surface::Shape::kPlane: break;
  }
  *hit = Hit{t, alpha, beta, nd};
  return true;
}

inline float Bilinear(const cv::Mat& level, float s, float t) {
  const int size = level.cols;  // square, power of two
  const int mask = size - 1;
  const float fs = s - 0.5f;
  const float ft = t - 0.5f;
  const float s0f = std::floor(fs);
  const float t0f = std::floor(ft);
  const float ws = fs - s0f;
  const float wt = ft - t0f;
  // Wrap in 64-bit first: far ground points can have texel coordinates beyond 2^31.
  const int s0 = static_cast<int>(static_cast<std::int64_t>(s0f) & mask);
  const int t0 = static_cast<int>(static_cast<std::int64_t>(t0f) & mask);
  const int s1 = (s0 + 1) & mask;
  const int t1 = (t0 + 1) & mask;
  const std::uint8_t* r0 = level.ptr<std::uint8_t>(t0);
  const std::uint8_t* r1 = level.ptr<std::uint8_t>(t1);
  const float top = r0[s0] + ws * (r0[s1] - r0[s0]);
  const float bottom = r1[s0] + ws * (r1[s1] - r1[s0]);
  return top + wt * (bottom - top);
}

inline float ShadeHit(const Prepared& p, const Hit& h, float anisotropy) {
  const Texture& tex = *p.texture;
  const float s = h.alpha * p.s_scale;
  const float t = h.beta * p.t_scale;
  const float abs_nd = std::max(std::abs(h.nd), 1e-6f);
  // Footprint of the pixel on the surface, in texels^2: t^2 / (f^2 texel^2 |n.d|); the
  // anisotropy term moves the choice towards the long side of the footprint.
  float lod = 0.5f * (FastLog2(h.t * h.t * p.lod_scale) - (1.0f + anisotropy) * FastLog2(abs_nd));
  const int max_level = static_cast<int>(tex.levels.size()) - 1;
  if (lod <= 0.0f) return p.shade * Bilinear(tex.levels[0], s, t);
  if (lod >= static_cast<float>(max_level)) return p.shade * tex.levels[max_level].at<std::uint8_t>(0, 0);
  const int l0 = static_cast<int>(lod);
  const float w = lod - static_cast<float>(l0);
  const float scale0 = 1.0f / static_cast<float>(1 << l0);
  const float v0 = Bilinear(tex.levels[l0], s * scale0, t * scale0);
  const float v1 = Bilinear(tex.levels[l0 + 1], s * scale0 * 0.5f, t * scale0 * 0.5f);
  return p.shade * (v0 + w * (v1 - v0));
}

// Clips a polygon (camera frame) to z >= near and returns its projected bounds, or false.
bool ScreenBounds(const std::vector<Eigen::Vector3d>& poly, const CameraModel& cam, double near_m,
                  int* x0, int* x1, int* y0, int* y1) {
  std::vector<Eigen::Vector3d> clipped;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = poly[i];
    const Eigen::Vector3d& b = poly[(i + 1) % n];
    const bool ina = a.z() >= near_m;
    const bool inb = b.z() >= near_m;
    if (ina) clipped.push_back(a);
    if (ina != inb) {
      const double t = (near_m - a.z()) / (b.z() - a.z());
      clipped.push_back(a + t * (b - a));
    }
  }
  if (clipped.empty()) return false;
  double minx = 1e30, maxx = -1e30, miny = 1e30, maxy = -1e30;
  for (const auto& p : clipped) {
    const double u = cam.fx * p.x() / p.z() + cam.cx;
    const double v = cam.fy * p.y() / p.z() + cam.cy;
    minx = std::min(minx, u);
    maxx = std::max(maxx, u);
    miny = std::min(miny, v);
    maxy = std::max(maxy, v);
  }
  const double lim = 1e6;
  *x0 = std::max(0, static_cast<int>(std::floor(std::max(minx, -lim))) - 1);
  *x1 = std::min(cam.width - 1, static_cast<int>(std::ceil(std::min(maxx, lim))) + 1);
  *y0 = std::max(0, static_cast<int>(std::floor(std::max(miny, -lim))) - 1);
  *y1 = std::min(cam.height - 1, static_cast<int>(std::ceil(std::min(maxy, lim))) + 1);
  return *x0 <= *x1 && *y0 <= *y1;
}

bool Prepare(const Surface& s, const CameraModel& cam, const Rigid3& camera_from_world,
             const RenderOptions& options, Prepared* out) {
  const Eigen::Matrix3d r = camera_from_world.linear();
  const Eigen::Vector3d o = camera_from_world * s.origin;
  const Eigen::Vector3d e1 = r * s.e1;
  const Eigen::Vector3d e2 = r * s.e2;
  Eigen::Vector3d n = e1.cross(e2);
  const double n_norm = n.norm();
  if (n_norm < 1e-12) return false;
  n /= n_norm;
  double k = n.dot(o);
  // One-sided surfaces face along e1 x e2: the camera (origin) must be on that side.
  if (s.one_sided && k >= 0.0) return false;
  if (std::abs(k) < 1e-9) return false;  // camera in the plane: edge-on

  Prepared p{};
  p.shape = s.shape;
  switch (s.shape) {
    case Surface::Shape::kParallelogram: {
      const std::vector<Eigen::Vector3d> poly = {o, o + e1, o + e1 + e2, o + e2};
      if (!ScreenBounds(poly, cam, options.near_m, &p.x0, &p.x1, &p.y0, &p.y1)) return false;
      break;
    }
    case Surface::Shape::kDisk: {
      const std::vector<Eigen::Vector3d> poly = {o - e1 - e2, o + e1 - e2, o + e1 + e2, o - e1 + e2};
      if (!ScreenBounds(poly, cam, options.near_m, &p.x0, &p.x1, &p.y0, &p.y1)) return false;
      break;
    }
    case Surface::Shape::kPlane:
      p.x0 = 0;
      p.x1 = cam.width - 1;
      p.y0 = 0;
      p.y1 = cam.height - 1;
      break;
  }
  // Directions d = (xd, yd, 1) with xd = (x - cx) / fx: fold the intrinsics into the coefficients
  // so that the inner loop works on pixel-independent (xd, yd).
  const Eigen::Vector3d a1 = e1 / e1.squaredNorm();
  const Eigen::Vector3d a2 = e2 / e2.squaredNorm();
  p.nx = static_cast<float>(n.x());
  p.ny = static_cast<float>(n.y());
  p.nz = static_cast<float>(n.z());
  p.k = static_cast<float>(k);
  p.a1x = static_cast<float>(a1.x());
  p.a1y = static_cast<float>(a1.y());
  p.a1z = static_cast<float>(a1.z());
  p.c1 = static_cast<float>(a1.dot(o));
  p.a2x = static_cast<float>(a2.x());
  p.a2y = static_cast<float>(a2.y());
  p.a2z = static_cast<float>(a2.z());
  p.c2 = static_cast<float>(a2.dot(o));
  const Texture& tex = *s.texture;
  const double size = tex.levels[0].cols;
  double texel_m = tex.texel_m;
  if (tex.fit) {
    p.s_scale = static_cast<float>(size);
    p.t_scale = static_cast<float>(size);
    texel_m = std::sqrt(e1.norm() * e2.norm()) / size;
  } else {
    p.s_scale = static_cast<float>(e1.norm() / texel_m);
    p.t_scale = static_cast<float>(e2.norm() / texel_m);
  }
  p.lod_scale = static_cast<float>(1.0 / (cam.fx * cam.fy * texel_m * texel_m));
  p.shade = s.shade;
  p.texture = &tex;
  *out = p;
  return true;
}

}  // namespace

void RenderOptions::Validate() const {
  MAPLESS_CHECK(edge_supersample >= 1 && edge_supersample <= 8,
                "RenderOptions.edge_supersample = " << edge_supersample << "; must be in [1, 8]");
  MAPLESS_CHECK(near_m > 0.0, "RenderOptions.near_m = " << near_m << "; must be > 0");
  MAPLESS_CHECK(far_m > near_m, "RenderOptions.far_m = " << far_m << "; must be > near_m");
  MAPLESS_CHECK(anisotropy >= 0.0 && anisotropy <= 1.0,
                "RenderOptions.anisotropy = " << anisotropy << "; must be in [0, 1]");
}

void AppendObjectSurfaces(const WorldObject& o, std::shared_ptr<const Texture> texture,
                          std::vector<Surface>* out) {
  auto add = [&](Surface::Shape shape, const Eigen::Vector3d& origin, const Eigen::Vector3d& e1,
                 const Eigen::Vector3d& e2, bool one_sided) {
    Surface s;
    s.shape = shape;
    s.origin = origin;
    s.e1 = e1;
    s.e2 = e2;
    s.one_sided = one_sided;
    s.shade = ShadeFor(e1.cross(e2));
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
      const Eigen::Vector3d e2 = -up * o.size_m.y();          // top to bottom, like the image
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
  std::map<std::tuple<int, std::uint64_t, double, bool, double, double, int, std::string>,
           std::shared_ptr<const Texture>>
      cache;
  auto texture_for = [&](const TextureSpec& spec) {
    const auto key = std::make_tuple(static_cast<int>(spec.type), spec.seed, spec.texel_m, spec.fit,
                                     spec.mean, spec.contrast, spec.size_px, spec.file);
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, GenerateTexture(spec)).first;
    return it->second;
  };
  for (const WorldObject& o : world.objects) AppendObjectSurfaces(o, texture_for(o.texture), &surfaces_);
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
  const float aniso = static_cast<float>(options_.anisotropy);

  std::vector<Prepared> prepared;
  prepared.reserve(surfaces_.size() + extra.size());
  for (const auto* list : {&surfaces_, &extra}) {
    for (const Surface& s : *list) {
      Prepared p;
      if (Prepare(s, cam, camera_from_world, options_, &p)) prepared.push_back(p);
    }
  }

  std::vector<float> xd(static_cast<std::size_t>(w));
  std::vector<float> yd(static_cast<std::size_t>(h));
  for (int x = 0; x < w; ++x) xd[static_cast<std::size_t>(x)] = static_cast<float>((x - cam.cx) / cam.fx);
  for (int y = 0; y < h; ++y) yd[static_cast<std::size_t>(y)] = static_cast<float>((y - cam.cy) / cam.fy);

  const std::size_t npix = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  std::vector<float> depth(npix, std::numeric_limits<float>::infinity());
  std::vector<std::int32_t> id(npix, -1);
  std::vector<Hit> hits(npix);

  // Pass 1: nearest surface per pixel centre.
  for (std::size_t si = 0; si < prepared.size(); ++si) {
    const Prepared& p = prepared[si];
    for (int y = p.y0; y <= p.y1; ++y) {
      const float yv = yd[static_cast<std::size_t>(y)];
      const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
      for (int x = p.x0; x <= p.x1; ++x) {
        Hit hit;
        if (!Intersect(p, xd[static_cast<std::size_t>(x)], yv, near_m, far_m, &hit)) continue;
        const std::size_t i = row + static_cast<std::size_t>(x);
        if (hit.t >= depth[i]) continue;
        depth[i] = hit.t;
        id[i] = static_cast<std::int32_t>(si);
        hits[i] = hit;
      }
    }
  }

  auto sky = [&](float yv) {
    // yv is the ray's vertical slope; map the image rows' range linearly.
    const float f = std::clamp((yv - yd.front()) / (yd.back() - yd.front()), 0.0f, 1.0f);
    return static_cast<float>(sky_top_ + f * (sky_horizon_ - sky_top_));
  };

  cv::Mat image(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y) {
    std::uint8_t* out = image.ptr<std::uint8_t>(y);
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row + static_cast<std::size_t>(x);
      const float v = id[i] < 0 ? sky(yd[static_cast<std::size_t>(y)])
                                : ShadeHit(prepared[static_cast<std::size_t>(id[i])], hits[i], aniso);
      out[x] = cv::saturate_cast<std::uint8_t>(v);
    }
  }

  // Pass 2: supersample silhouette pixels, where the visible surface differs from a neighbour.
  const int ss = options_.edge_supersample;
  if (ss <= 1) return image;
  const float sub_x = static_cast<float>(1.0 / cam.fx);
  const float sub_y = static_cast<float>(1.0 / cam.fy);
  // Mark both pixels of every horizontally or vertically adjacent pair that sees different
  // surfaces (or a surface and the sky).
  std::vector<std::uint8_t> edge(npix, 0);
  for (int y = 0; y < h; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row + static_cast<std::size_t>(x);
      if (x + 1 < w && id[i] != id[i + 1]) edge[i] = edge[i + 1] = 1;
      if (y + 1 < h && id[i] != id[i + static_cast<std::size_t>(w)]) {
        edge[i] = edge[i + static_cast<std::size_t>(w)] = 1;
      }
    }
  }
  std::vector<std::int32_t> candidates;
  for (int y = 0; y < h; ++y) {
    std::uint8_t* out = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                            static_cast<std::size_t>(x);
      if (!edge[i]) continue;
      // Surfaces seen in the 3x3 neighbourhood: the candidates for this pixel's sub-rays.
      candidates.clear();
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= h) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= w) continue;
          const std::int32_t nid = id[static_cast<std::size_t>(yy) * static_cast<std::size_t>(w) +
                                      static_cast<std::size_t>(xx)];
          if (std::find(candidates.begin(), candidates.end(), nid) == candidates.end()) {
            candidates.push_back(nid);
          }
        }
      }
      float sum = 0.0f;
      for (int sy = 0; sy < ss; ++sy) {
        const float yv = yd[static_cast<std::size_t>(y)] + ((sy + 0.5f) / ss - 0.5f) * sub_y;
        for (int sx = 0; sx < ss; ++sx) {
          const float xv = xd[static_cast<std::size_t>(x)] + ((sx + 0.5f) / ss - 0.5f) * sub_x;
          float best_t = std::numeric_limits<float>::infinity();
          const Prepared* best = nullptr;
          Hit best_hit{};
          for (const std::int32_t c : candidates) {
            if (c < 0) continue;
            Hit hit;
            const Prepared& p = prepared[static_cast<std::size_t>(c)];
            if (Intersect(p, xv, yv, near_m, far_m, &hit) && hit.t < best_t) {
              best_t = hit.t;
              best = &p;
              best_hit = hit;
            }
          }
          sum += best ? ShadeHit(*best, best_hit, aniso) : sky(yv);
        }
      }
      out[x] = cv::saturate_cast<std::uint8_t>(sum / static_cast<float>(ss * ss));
    }
  }
  return image;
}

}  // namespace mapless::sim

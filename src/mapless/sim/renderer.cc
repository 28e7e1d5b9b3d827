#include "mapless/sim/renderer.h"

#include <algorithm>
#include <array>
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

float ShadeFor(const Eigen::Vector3d& normal, const Eigen::Vector3d& light) {
  return static_cast<float>(0.6 + 0.4 * std::abs(normal.normalized().dot(light)));
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
  float lod_base;          // mip level = lod_base - lod_slope * log2|n . d| (see ShadeHit)
  float shade;
  const Texture::LevelView* levels;  // mip pyramid, levels[0] finest
  int max_level;
  int x0, x1, y0, y1;  // inclusive screen bounds
  int group;           // edge group (see Surface::edge_group), made unique per render
};

struct Hit {
  float t;
  float alpha;
  float beta;
  float nd;
};

// Bilinear sample of one mip level in fixed point. (s_fx, t_fx) are level-0 texel coordinates
// times 256; level l is reached by an arithmetic shift (a floor, also for negative coordinates).
// Returns the grey level times 65536.
inline int BilinearFixed(const Texture::LevelView& level, int level_index, std::int64_t s_fx,
                         std::int64_t t_fx) {
  const int mask = (1 << level.log2_size) - 1;
  const std::int64_t sf = (s_fx >> level_index) - 128;  // texel centres at +0.5
  const std::int64_t tf = (t_fx >> level_index) - 128;
  const int ws = static_cast<int>(sf & 255);
  const int wt = static_cast<int>(tf & 255);
  const int s0 = static_cast<int>((sf >> 8) & mask);
  const int t0 = static_cast<int>((tf >> 8) & mask);
  const int s1 = (s0 + 1) & mask;
  const int t1 = (t0 + 1) & mask;
  const std::uint8_t* r0 = level.data + (t0 << level.log2_size);
  const std::uint8_t* r1 = level.data + (t1 << level.log2_size);
  const int top = (r0[s0] << 8) + ws * (r0[s1] - r0[s0]);
  const int bottom = (r1[s0] << 8) + ws * (r1[s1] - r1[s0]);
  return (top << 8) + wt * (bottom - top);
}

// `lod_slope` is 0.5 (3 + anisotropy), fixed per render.
inline float ShadeHit(const Prepared& p, const Hit& h, float lod_slope) {
  // Level-0 texel coordinates in 24.8 fixed point (hits are nearer than far_m, so they fit).
  const auto s_fx = static_cast<std::int64_t>(h.alpha * p.s_scale * 256.0f);
  const auto t_fx = static_cast<std::int64_t>(h.beta * p.t_scale * 256.0f);
  // Footprint of the pixel on the surface in texels^2 is t^2 / (f^2 texel^2 |n.d|), and the
  // anisotropy a moves the choice towards its long side: level = 0.5 log2(t^2 L / |n.d|^(1+a)).
  // With t = k / (n.d) this is 0.5 log2(k^2 L) - 0.5 (3 + a) log2|n.d|: one log per pixel.
  const float lod = p.lod_base - lod_slope * FastLog2(std::max(std::abs(h.nd), 1e-6f));
  constexpr float kInv16 = 1.0f / 65536.0f;
  if (lod <= 0.0f)
    return p.shade * kInv16 * static_cast<float>(BilinearFixed(p.levels[0], 0, s_fx, t_fx));
  if (lod >= static_cast<float>(p.max_level)) return p.shade * p.levels[p.max_level].data[0];
  const int l0 = static_cast<int>(lod);
  const float w = lod - static_cast<float>(l0);
  const auto v0 = static_cast<float>(BilinearFixed(p.levels[l0], l0, s_fx, t_fx));
  const auto v1 = static_cast<float>(BilinearFixed(p.levels[l0 + 1], l0 + 1, s_fx, t_fx));
  return p.shade * kInv16 * (v0 + w * (v1 - v0));
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
      const std::vector<Eigen::Vector3d> poly = {o - e1 - e2, o + e1 - e2, o + e1 + e2,
                                                 o - e1 + e2};
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
  p.lod_base = static_cast<float>(0.5 * std::log2(k * k / (cam.fx * cam.fy * texel_m * texel_m)));
  p.shade = s.shade;
  p.levels = tex.views.data();
  p.max_level = static_cast<int>(tex.views.size()) - 1;
  *out = p;
  return true;
}

// Branchless selects written with bit masks: GCC turns `a[i] = c ? x : a[i]` into a conditional
// store, which blocks vectorisation; these keep the loops below straight-line.
inline float Select(bool c, float a, float b) {
  std::uint32_t ua = 0;
  std::uint32_t ub = 0;
  std::memcpy(&ua, &a, sizeof(ua));
  std::memcpy(&ub, &b, sizeof(ub));
  const std::uint32_t m = 0u - static_cast<std::uint32_t>(c);
  const std::uint32_t r = (ua & m) | (ub & ~m);
  float out = 0.0f;
  std::memcpy(&out, &r, sizeof(out));
  return out;
}

inline std::int32_t Select(bool c, std::int32_t a, std::int32_t b) {
  const std::int32_t m = -static_cast<std::int32_t>(c);
  return (a & m) | (b & ~m);
}

// Per-pixel results of pass 1, as structure of arrays.
struct Buffers {
  std::vector<float> depth;
  std::vector<std::int32_t> id;
  std::vector<float> alpha;
  std::vector<float> beta;
  std::vector<float> nd;
};

// One row of pass 1 for one surface. Restrict-qualified parameters tell the compiler that the
// buffers do not overlap, so that the loop vectorises.
template <Surface::Shape kShape>
void RasterRow(const Prepared& p, std::int32_t index, float nd_row, float a1_row, float a2_row,
               float near_m, float far_m, const float* __restrict xs, float* __restrict depth,
               std::int32_t* __restrict id, float* __restrict alpha_out, float* __restrict beta_out,
               float* __restrict nd_out) {
  const float nx = p.nx, k = p.k, a1x = p.a1x, c1 = p.c1, a2x = p.a2x, c2 = p.c2;
  const int x_begin = p.x0;
  const int x_end = p.x1 + 1;  // half-open, so that the trip count is computable
  for (int x = x_begin; x < x_end; ++x) {
    const float xv = xs[x];
    const float nd = nx * xv + nd_row;
    const float t = k / nd;  // nd = 0 gives inf or nan: every comparison below is false
    const float alpha = t * (a1x * xv + a1_row) - c1;
    const float beta = t * (a2x * xv + a2_row) - c2;
    bool inside = true;
    if (kShape == Surface::Shape::kParallelogram) {
      inside = (alpha >= 0.0f) & (alpha <= 1.0f) & (beta >= 0.0f) & (beta <= 1.0f);
    } else if (kShape == Surface::Shape::kDisk) {
      inside = alpha * alpha + beta * beta <= 1.0f;
    }
    const float d = depth[x];
    const bool hit = inside & (t > near_m) & (t < far_m) & (t < d);
    depth[x] = Select(hit, t, d);
    id[x] = Select(hit, index, id[x]);
    alpha_out[x] = Select(hit, alpha, alpha_out[x]);
    beta_out[x] = Select(hit, beta, beta_out[x]);
    nd_out[x] = Select(hit, nd, nd_out[x]);
  }
}

template <Surface::Shape kShape>
void RasterSurface(const Prepared& p, std::int32_t index, const std::vector<float>& xd,
                   const std::vector<float>& yd, int w, float near_m, float far_m, Buffers* buf) {
  float* depth = buf->depth.data();
  std::int32_t* id = buf->id.data();
  float* alpha_out = buf->alpha.data();
  float* beta_out = buf->beta.data();
  float* nd_out = buf->nd.data();
  const float* xs = xd.data();
  for (int y = p.y0; y <= p.y1; ++y) {
    const float yv = yd[static_cast<std::size_t>(y)];
    const float nd_row = p.ny * yv + p.nz;
    if (kShape == Surface::Shape::kPlane) {
      // Skip rows wholly beyond the horizon (t < 0 at both ends; n . d is linear along the row).
      const float nd0 = p.nx * xs[p.x0] + nd_row;
      const float nd1 = p.nx * xs[p.x1] + nd_row;
      if (p.k * nd0 <= 0.0f && p.k * nd1 <= 0.0f) continue;
    }
    const float a1_row = p.a1y * yv + p.a1z;
    const float a2_row = p.a2y * yv + p.a2z;
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * w;
    RasterRow<kShape>(p, index, nd_row, a1_row, a2_row, near_m, far_m, xs, depth + row, id + row,
                      alpha_out + row, beta_out + row, nd_out + row);
  }
}

// The sub-rays of one silhouette pixel and, per sub-ray, the nearest hit so far.
constexpr int kMaxSubRays = 64;  // edge_supersample <= 8
struct SubRayBuffers {
  float xv[kMaxSubRays];
  float yv[kMaxSubRays];
  float t[kMaxSubRays];
  float alpha[kMaxSubRays];
  float beta[kMaxSubRays];
  float nd[kMaxSubRays];
  std::int32_t winner[kMaxSubRays];
};

// Tests every sub-ray against one candidate surface (branchless, so that it vectorises).
template <Surface::Shape kShape>
void SubRays(const Prepared& p, std::int32_t candidate, int n, float near_m, float far_m,
             SubRayBuffers* b) {
  for (int k = 0; k < n; ++k) {
    const float xv = b->xv[k];
    const float yv = b->yv[k];
    const float nd = p.nx * xv + p.ny * yv + p.nz;
    const float t = p.k / nd;
    const float alpha = t * (p.a1x * xv + p.a1y * yv + p.a1z) - p.c1;
    const float beta = t * (p.a2x * xv + p.a2y * yv + p.a2z) - p.c2;
    bool inside = true;
    if (kShape == Surface::Shape::kParallelogram) {
      inside = (alpha >= 0.0f) & (alpha <= 1.0f) & (beta >= 0.0f) & (beta <= 1.0f);
    } else if (kShape == Surface::Shape::kDisk) {
      inside = alpha * alpha + beta * beta <= 1.0f;
    }
    const float best = b->t[k];
    const bool hit = inside & (t > near_m) & (t < far_m) & (t < best);
    b->t[k] = Select(hit, t, best);
    b->alpha[k] = Select(hit, alpha, b->alpha[k]);
    b->beta[k] = Select(hit, beta, b->beta[k]);
    b->nd[k] = Select(hit, nd, b->nd[k]);
    b->winner[k] = Select(hit, candidate, b->winner[k]);
  }
}

// The surfaces of the world and the extra ones, prepared for this camera pose (those behind the
// camera or outside the view are left out); a surface's group ties the faces of one object.
std::vector<Prepared> PrepareSurfaces(const std::vector<Surface>& own,
                                      const std::vector<Surface>& extra, const CameraModel& cam,
                                      const Rigid3& camera_from_world,
                                      const RenderOptions& options) {
  std::vector<Prepared> prepared;
  prepared.reserve(own.size() + extra.size());
  int list_offset = 0;
  const int group_base = 1 << 20;  // grouped surfaces: group_base + list offset + edge_group
  for (const auto* list : {&own, &extra}) {
    for (std::size_t k = 0; k < list->size(); ++k) {
      const Surface& s = (*list)[k];
      Prepared p;
      if (!Prepare(s, cam, camera_from_world, options, &p)) continue;
      p.group = s.edge_group >= 0 ? group_base + list_offset + s.edge_group
                                  : static_cast<int>(prepared.size());
      prepared.push_back(p);
    }
    list_offset += static_cast<int>(list->size());
  }

  return prepared;
}

// Pass 1: the nearest surface per pixel centre. Branchless over structure-of-arrays buffers so
// that the compiler vectorises the ray-surface tests.
void RasterNearest(const std::vector<Prepared>& prepared, const std::vector<float>& xd,
                   const std::vector<float>& yd, int w, float near_m, float far_m, Buffers* out) {
  Buffers& buf = *out;
  for (std::size_t si = 0; si < prepared.size(); ++si) {
    const Prepared& p = prepared[si];
    switch (p.shape) {
      case Surface::Shape::kParallelogram:
        RasterSurface<Surface::Shape::kParallelogram>(p, static_cast<std::int32_t>(si), xd, yd, w,
                                                      near_m, far_m, &buf);
        break;
      case Surface::Shape::kDisk:
        RasterSurface<Surface::Shape::kDisk>(p, static_cast<std::int32_t>(si), xd, yd, w, near_m,
                                             far_m, &buf);
        break;
      case Surface::Shape::kPlane:
        RasterSurface<Surface::Shape::kPlane>(p, static_cast<std::int32_t>(si), xd, yd, w, near_m,
                                              far_m, &buf);
        break;
    }
  }
}

// The sky's grey level for a ray's vertical slope: the image rows' range mapped linearly from the
// top of the sky to the horizon.
struct SkyRamp {
  double top = 0.0;
  double horizon = 0.0;
  float first_row = 0.0f;  // the slopes of the first and the last image row
  float last_row = 0.0f;
  float operator()(float yv) const {
    const float f = std::clamp((yv - first_row) / (last_row - first_row), 0.0f, 1.0f);
    return static_cast<float>(top + f * (horizon - top));
  }
};

// Pass 2: silhouette pixels (where the visible surface differs from a neighbour's) supersampled
// S x S, each surface that wins sub-rays shaded once at the centroid of its hits.
void SupersampleEdges(const std::vector<Prepared>& prepared, const Buffers& buf,
                      const std::vector<float>& xd, const std::vector<float>& yd,
                      const CameraModel& cam, int ss, float near_m, float far_m, float lod_slope,
                      const SkyRamp& sky, cv::Mat* image) {
  const int w = cam.width;
  const int h = cam.height;
  const std::size_t npix = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const std::vector<std::int32_t>& id = buf.id;
  const float sub_x = static_cast<float>(1.0 / cam.fx);
  const float sub_y = static_cast<float>(1.0 / cam.fy);
  // Mark both pixels of every horizontally or vertically adjacent pair that sees different
  // surfaces (or a surface and the sky).
  thread_local std::vector<std::int32_t> group;  // kept between renders, as Render's buffers
  thread_local std::vector<std::uint8_t> edge;
  group.resize(npix);
  for (std::size_t i = 0; i < npix; ++i) {
    group[i] = id[i] < 0 ? -1 : prepared[static_cast<std::size_t>(id[i])].group;
  }
  edge.assign(npix, 0);
  for (int y = 0; y < h; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row + static_cast<std::size_t>(x);
      if (x + 1 < w && group[i] != group[i + 1]) edge[i] = edge[i + 1] = 1;
      if (y + 1 < h && group[i] != group[i + static_cast<std::size_t>(w)]) {
        edge[i] = edge[i + static_cast<std::size_t>(w)] = 1;
      }
    }
  }
  struct Accum {
    float t = 0.0f, alpha = 0.0f, beta = 0.0f, nd = 0.0f;
    int n = 0;
  };
  std::vector<std::int32_t> candidates;
  candidates.reserve(9);
  std::array<Accum, 9> accum{};
  const int nsub = ss * ss;
  std::vector<float> sub_dx(static_cast<std::size_t>(nsub));
  std::vector<float> sub_dy(static_cast<std::size_t>(nsub));
  for (int sy = 0; sy < ss; ++sy) {
    for (int sx = 0; sx < ss; ++sx) {
      sub_dx[static_cast<std::size_t>(sy * ss + sx)] = ((sx + 0.5f) / ss - 0.5f) * sub_x;
      sub_dy[static_cast<std::size_t>(sy * ss + sx)] = ((sy + 0.5f) / ss - 0.5f) * sub_y;
    }
  }
  SubRayBuffers sub;
  for (int y = 0; y < h; ++y) {
    std::uint8_t* out = image->ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      const std::size_t i =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
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
      // Coverage by S x S sub-rays; each surface that wins sub-rays is shaded once, at the
      // centroid of its winning hits (multisample anti-aliasing), the sky per sub-ray.
      const float xc = xd[static_cast<std::size_t>(x)];
      const float yc = yd[static_cast<std::size_t>(y)];
      for (int k = 0; k < nsub; ++k) {
        sub.xv[k] = xc + sub_dx[static_cast<std::size_t>(k)];
        sub.yv[k] = yc + sub_dy[static_cast<std::size_t>(k)];
        sub.t[k] = std::numeric_limits<float>::infinity();
        sub.winner[k] = -1;
      }
      for (std::size_t c = 0; c < candidates.size(); ++c) {
        if (candidates[c] < 0) continue;
        const Prepared& p = prepared[static_cast<std::size_t>(candidates[c])];
        const auto ci = static_cast<std::int32_t>(c);
        switch (p.shape) {
          case Surface::Shape::kParallelogram:
            SubRays<Surface::Shape::kParallelogram>(p, ci, nsub, near_m, far_m, &sub);
            break;
          case Surface::Shape::kDisk:
            SubRays<Surface::Shape::kDisk>(p, ci, nsub, near_m, far_m, &sub);
            break;
          case Surface::Shape::kPlane:
            SubRays<Surface::Shape::kPlane>(p, ci, nsub, near_m, far_m, &sub);
            break;
        }
      }
      for (Accum& a : accum) a = Accum{};
      float sky_sum = 0.0f;
      for (int k = 0; k < nsub; ++k) {
        if (sub.winner[k] < 0) {
          sky_sum += sky(sub.yv[k]);
          continue;
        }
        Accum& a = accum[static_cast<std::size_t>(sub.winner[k])];
        a.t += sub.t[k];
        a.alpha += sub.alpha[k];
        a.beta += sub.beta[k];
        a.nd += sub.nd[k];
        ++a.n;
      }
      float sum = sky_sum;
      for (std::size_t c = 0; c < candidates.size(); ++c) {
        const Accum& a = accum[c];
        if (a.n == 0) continue;
        const float inv = 1.0f / static_cast<float>(a.n);
        const Hit mean{a.t * inv, a.alpha * inv, a.beta * inv, a.nd * inv};
        sum += static_cast<float>(a.n) *
               ShadeHit(prepared[static_cast<std::size_t>(candidates[c])], mean, lod_slope);
      }
      out[x] = cv::saturate_cast<std::uint8_t>(sum / static_cast<float>(ss * ss));
    }
  }
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
  const std::vector<Prepared> prepared =
      PrepareSurfaces(surfaces_, extra, cam, camera_from_world, options_);
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
  thread_local Buffers buf;
  buf.depth.assign(npix, std::numeric_limits<float>::infinity());
  buf.id.assign(npix, -1);
  buf.alpha.resize(npix);
  buf.beta.resize(npix);
  buf.nd.resize(npix);

  RasterNearest(prepared, xd, yd, w, near_m, far_m, &buf);
  const std::vector<float>& depth = buf.depth;
  const std::vector<std::int32_t>& id = buf.id;
  const SkyRamp sky{sky_top_, sky_horizon_, yd.front(), yd.back()};

  cv::Mat image(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y) {
    std::uint8_t* out = image.ptr<std::uint8_t>(y);
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    const float sky_row = sky(yd[static_cast<std::size_t>(y)]);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row + static_cast<std::size_t>(x);
      const float v =
          id[i] < 0 ? sky_row
                    : ShadeHit(prepared[static_cast<std::size_t>(id[i])],
                               Hit{depth[i], buf.alpha[i], buf.beta[i], buf.nd[i]}, lod_slope);
      out[x] = cv::saturate_cast<std::uint8_t>(v);
    }
  }

  // Pass 2: supersample silhouette pixels, where the visible surface differs from a neighbour.
  const int ss = options_.edge_supersample;
  if (ss > 1)
    SupersampleEdges(prepared, buf, xd, yd, cam, ss, near_m, far_m, lod_slope, sky, &image);
  return image;
}

}  // namespace mapless::sim

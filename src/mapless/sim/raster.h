// The renderer's per-pixel core (renderer.cc): surfaces prepared for one camera, the nearest
// surface per pixel (raster.cc) and the supersampled silhouettes (supersample.cc). Internal to
// sim/; the hot loops are written to vectorise (sim/CMakeLists.txt compiles these files with the
// flags that let them).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

#include "mapless/sim/renderer.h"

namespace mapless::sim::raster {

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
// Both forced inline: clang does not inline them under AddressSanitizer (instrumentation makes them
// look large), and a call per pixel was a sixth of `mapless demo`'s time in the sanitizer build.
[[gnu::always_inline]] inline int BilinearFixed(const Texture::LevelView& level, int level_index,
                                                std::int64_t s_fx, std::int64_t t_fx) {
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

// A surface coordinate (alpha or beta) in level-0 texels, times 256: the 24.8 fixed-point texture
// coordinate before its conversion to an integer (ShadeHit's, and the shading kernel's).
inline float TexelTimes256(float coordinate, float texels_per_unit) {
  return coordinate * texels_per_unit * 256.0f;
}

// The mip level of a hit with n . d = nd. Footprint of the pixel on the surface in texels^2 is
// t^2 / (f^2 texel^2 |n.d|), and the anisotropy a moves the choice towards its long side:
// level = 0.5 log2(t^2 L / |n.d|^(1+a)). With t = k / (n.d) this is
// 0.5 log2(k^2 L) - 0.5 (3 + a) log2|n.d|: one log per pixel. `lod_slope` is 0.5 (3 + a), fixed
// per render. max(|nd|, 1e-6) is written as a select, so that loops over it vectorise.
inline float MipLevel(const Prepared& p, float nd, float lod_slope) {
  const float abs_nd = std::abs(nd);
  return p.lod_base - lod_slope * FastLog2(Select(abs_nd < 1e-6f, 1e-6f, abs_nd));
}

// `lod_slope` is 0.5 (3 + anisotropy), fixed per render.
[[gnu::always_inline]] inline float ShadeHit(const Prepared& p, const Hit& h, float lod_slope) {
  // Level-0 texel coordinates in 24.8 fixed point (hits are nearer than far_m, so they fit).
  const auto s_fx = static_cast<std::int64_t>(TexelTimes256(h.alpha, p.s_scale));
  const auto t_fx = static_cast<std::int64_t>(TexelTimes256(h.beta, p.t_scale));
  const float lod = MipLevel(p, h.nd, lod_slope);
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

// Per-pixel results of pass 1, as structure of arrays.
struct Buffers {
  std::vector<float> depth;
  std::vector<std::int32_t> id;
  std::vector<float> alpha;
  std::vector<float> beta;
  std::vector<float> nd;
};

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

// The surfaces of the world and the extra ones, prepared for this camera pose (those behind the
// camera or outside the view are left out); a surface's group ties the faces of one object.
std::vector<Prepared> PrepareSurfaces(const std::vector<Surface>& own,
                                      const std::vector<Surface>& extra, const CameraModel& cam,
                                      const Rigid3& camera_from_world,
                                      const RenderOptions& options);

// The kernels: the per-pixel passes, each compiled for the baseline and, on x86-64, for AVX2
// (kernel_target.h). Both give the same bytes; Kernels() picks the one the CPU runs.
#define MAPLESS_SIM_KERNEL_DECLARATIONS                                                     \
  /* Pass 1: the nearest surface per pixel centre. Branchless over structure-of-arrays */   \
  /* buffers so that the compiler vectorises the ray-surface tests (nearest.cc). */         \
  void RasterNearest(const std::vector<Prepared>& prepared, const std::vector<float>& xd,   \
                     const std::vector<float>& yd, int w, float near_m, float far_m,        \
                     Buffers* out);                                                         \
  /* Pass 1b: every pixel shaded from the surface pass 1 found there (ShadeHit's bytes), */ \
  /* the sky where there is none (shade.cc). */                                             \
  void ShadeImage(const std::vector<Prepared>& prepared, const Buffers& buf,                \
                  const std::vector<float>& yd, const SkyRamp& sky, float lod_slope,        \
                  cv::Mat* image);                                                          \
  /* Pass 2: silhouette pixels (where the visible surface differs from a neighbour's) */    \
  /* supersampled S x S, each surface that wins sub-rays shaded once at the centroid of */  \
  /* its hits (supersample.cc). */                                                          \
  void SupersampleEdges(const std::vector<Prepared>& prepared, const Buffers& buf,          \
                        const std::vector<float>& xd, const std::vector<float>& yd,         \
                        const CameraModel& cam, int ss, float near_m, float far_m,          \
                        float lod_slope, const SkyRamp& sky, cv::Mat* image);

namespace baseline {
MAPLESS_SIM_KERNEL_DECLARATIONS
}  // namespace baseline
namespace avx2 {
MAPLESS_SIM_KERNEL_DECLARATIONS
}  // namespace avx2
#undef MAPLESS_SIM_KERNEL_DECLARATIONS

// One build of the three kernels.
struct KernelSet {
  const char* name;  // "baseline" or "avx2"
  decltype(&baseline::RasterNearest) raster_nearest;
  decltype(&baseline::ShadeImage) shade_image;
  decltype(&baseline::SupersampleEdges) supersample_edges;
};

// The AVX2 build where the CPU (and the operating system) runs AVX2, the baseline otherwise, or
// the baseline always after UseBaselineRenderKernels(true) (renderer.h).
const KernelSet& Kernels();

}  // namespace mapless::sim::raster

// Pass 1 of the renderer (raster.h): the nearest surface per pixel centre. A kernel file
// (kernel_target.h): compiled for the baseline and for AVX2.
#include <cstdint>
#include <vector>

#include "mapless/sim/kernel_target.h"
#include "mapless/sim/raster.h"

namespace mapless::sim::raster::MAPLESS_KERNEL_NS {
namespace {

// One row of pass 1 for one surface. Restrict-qualified parameters tell the compiler that the
// buffers do not overlap, so that the loop vectorises.
template <Surface::Shape kShape>
MAPLESS_KERNEL void RasterRow(const Prepared& p, std::int32_t index, float nd_row, float a1_row,
                              float a2_row, float near_m, float far_m, const float* __restrict xs,
                              float* __restrict depth, std::int32_t* __restrict id,
                              float* __restrict alpha_out, float* __restrict beta_out,
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
MAPLESS_KERNEL void RasterSurface(const Prepared& p, std::int32_t index,
                                  const std::vector<float>& xd, const std::vector<float>& yd, int w,
                                  float near_m, float far_m, Buffers* buf) {
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

}  // namespace

// Pass 1: the nearest surface per pixel centre. Branchless over structure-of-arrays buffers so
// that the compiler vectorises the ray-surface tests.
MAPLESS_KERNEL void RasterNearest(const std::vector<Prepared>& prepared,
                                  const std::vector<float>& xd, const std::vector<float>& yd, int w,
                                  float near_m, float far_m, Buffers* out) {
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

}  // namespace mapless::sim::raster::MAPLESS_KERNEL_NS

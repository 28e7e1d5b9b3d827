// Pass 2 of the renderer (raster.h): silhouette pixels supersampled.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "mapless/sim/kernel_target.h"
#include "mapless/sim/raster.h"

namespace mapless::sim::raster::MAPLESS_KERNEL_NS {
namespace {

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
MAPLESS_KERNEL void SubRays(const Prepared& p, std::int32_t candidate, int n, float near_m,
                            float far_m, SubRayBuffers* b) {
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

// Marks the pixels of one row whose group differs from a neighbour's (left, right, up, down),
// branchless so that it vectorises.
MAPLESS_KERNEL void MarkEdges(const std::int32_t* __restrict g, const std::int32_t* __restrict up,
                              const std::int32_t* __restrict down, int w,
                              std::uint8_t* __restrict e) {
  if (w == 1) {
    e[0] = static_cast<std::uint8_t>((g[0] != up[0]) | (g[0] != down[0]));
    return;
  }
  e[0] = static_cast<std::uint8_t>((g[0] != g[1]) | (g[0] != up[0]) | (g[0] != down[0]));
  for (int x = 1; x + 1 < w; ++x) {
    e[x] = static_cast<std::uint8_t>((g[x] != g[x - 1]) | (g[x] != g[x + 1]) | (g[x] != up[x]) |
                                     (g[x] != down[x]));
  }
  const int l = w - 1;
  e[l] = static_cast<std::uint8_t>((g[l] != g[l - 1]) | (g[l] != up[l]) | (g[l] != down[l]));
}

// Marks every pixel that sees another surface group (or a surface and the sky) than one of its
// four neighbours: the pixels of every adjacent pair that differs. Returns a per-thread buffer,
// kept between renders as Render's buffers.
MAPLESS_KERNEL const std::vector<std::uint8_t>& SilhouettePixels(
    const std::vector<Prepared>& prepared, const std::vector<std::int32_t>& id, int w, int h) {
  const std::size_t npix = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  thread_local std::vector<std::int32_t> group;
  thread_local std::vector<std::int32_t> group_of;
  thread_local std::vector<std::uint8_t> edge;
  group_of.resize(prepared.size() + 1);
  group_of[0] = -1;  // the sky
  for (std::size_t k = 0; k < prepared.size(); ++k) group_of[k + 1] = prepared[k].group;
  group.resize(npix);
  edge.resize(npix);
  for (std::size_t i = 0; i < npix; ++i) group[i] = group_of[static_cast<std::size_t>(id[i] + 1)];
  for (int y = 0; y < h; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    const std::int32_t* g = group.data() + row;
    // The first and the last row compare with themselves where there is no row beyond.
    const std::int32_t* up = y > 0 ? g - w : g;
    const std::int32_t* down = y + 1 < h ? g + w : g;
    MarkEdges(g, up, down, w, edge.data() + row);
  }
  return edge;
}

}  // namespace

// Pass 2: silhouette pixels (where the visible surface differs from a neighbour's) supersampled
// S x S, each surface that wins sub-rays shaded once at the centroid of its hits.
MAPLESS_KERNEL void SupersampleEdges(const std::vector<Prepared>& prepared, const Buffers& buf,
                                     const std::vector<float>& xd, const std::vector<float>& yd,
                                     const CameraModel& cam, int ss, float near_m, float far_m,
                                     float lod_slope, const SkyRamp& sky, cv::Mat* image) {
  const int w = cam.width;
  const int h = cam.height;
  const std::vector<std::int32_t>& id = buf.id;
  const float sub_x = static_cast<float>(1.0 / cam.fx);
  const float sub_y = static_cast<float>(1.0 / cam.fy);
  const std::vector<std::uint8_t>& edge = SilhouettePixels(prepared, id, w, h);
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
    const std::uint8_t* e = edge.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    for (int x = 0; x < w; ++x) {
      // Skip eight pixels at a time where none is on an edge (most of the image).
      std::uint64_t eight = 0;
      if (x + 8 <= w) std::memcpy(&eight, e + x, sizeof(eight));
      if (x + 8 <= w && eight == 0) {
        x += 7;
        continue;
      }
      if (!e[x]) continue;
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

}  // namespace mapless::sim::raster::MAPLESS_KERNEL_NS

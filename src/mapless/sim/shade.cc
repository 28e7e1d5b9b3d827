// Pass 1b of the renderer (raster.h): every pixel shaded from the surface pass 1 found there.
//
// The same arithmetic as ShadeHit, pixel for pixel, organised for the vectoriser: a row is cut
// into segments that see one surface at one mip level (or one of the cases without a level pair),
// and each segment is shaded in chunks by loops without branches or per-pixel shift counts. Only
// the texel fetches stay scalar. A run whose fixed-point texture coordinates do not fit 32 bits
// (never on the built-in worlds; a ground of 10 um texels a kilometre from the origin) is shaded
// by ShadeHit itself, so the bytes are ShadeHit's in every case
// (`RendererKernels.ShadingGivesShadeHitsBytesPixelForPixel`). A kernel file (kernel_target.h).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "mapless/sim/kernel_target.h"
#include "mapless/sim/raster.h"

namespace mapless::sim::raster::MAPLESS_KERNEL_NS {
namespace {

constexpr int kChunk = 64;
constexpr std::int32_t kKeyFinest = -2;    // lod <= 0: one bilinear sample of level 0
constexpr std::int32_t kKeyCoarsest = -1;  // lod >= the last level: its single texel

// Round half to even, as cvRound in the default rounding mode, then clamp to a byte: the bytes of
// cv::saturate_cast<uint8_t>(float) for every finite value. Adding and subtracting 1.5 * 2^23
// rounds any |v| < 2^22 to an integer; larger values clamp to 0 or 255 either way.
MAPLESS_KERNEL inline std::uint8_t RoundToByte(float v) {
  const float r = (v + 12582912.0f) - 12582912.0f;
  return static_cast<std::uint8_t>(static_cast<std::int32_t>(std::clamp(r, 0.0f, 255.0f)));
}

// The per-pixel values of one run of pixels that see the same surface.
struct RunValues {
  std::int32_t s[kChunk];  // level-0 texel coordinates in 24.8 fixed point (ShadeHit's s_fx)
  std::int32_t t[kChunk];
  float w[kChunk];           // weight of the coarser level of the pair
  std::int32_t key[kChunk];  // the level pair's finer level, or one of kKey*
};

// Bilinear samples of one level for n pixels: BilinearFixed's values, the fetches gathered first
// so that the arithmetic vectorises. The arithmetic is BilinearFixed's in float: every operand and
// result is an integer below 2^24 in magnitude, so each operation is exact and the value is the
// same (SSE2 has no 32-bit integer multiply that vectorises well; its float multiply does).
MAPLESS_KERNEL void SampleLevel(const Texture::LevelView& level, int level_index,
                                const std::int32_t* s, const std::int32_t* t, int n, float* out) {
  const int log2 = level.log2_size;
  const std::int32_t mask = (1 << log2) - 1;
  std::int32_t ws[kChunk], wt[kChunk], o00[kChunk], ds[kChunk], dt[kChunk];
  for (int i = 0; i < n; ++i) {
    const std::int32_t sf = (s[i] >> level_index) - 128;
    const std::int32_t tf = (t[i] >> level_index) - 128;
    ws[i] = sf & 255;
    wt[i] = tf & 255;
    const std::int32_t s0 = (sf >> 8) & mask;
    const std::int32_t t0 = (tf >> 8) & mask;
    o00[i] = (t0 << log2) + s0;
    ds[i] = ((s0 + 1) & mask) - s0;
    dt[i] = (((t0 + 1) & mask) - t0) << log2;
  }
  std::int32_t a[kChunk], b[kChunk], c[kChunk], d[kChunk];
  const std::uint8_t* data = level.data;
  for (int i = 0; i < n; ++i) {
    const std::uint8_t* r0 = data + o00[i];
    const std::uint8_t* r1 = r0 + dt[i];
    a[i] = r0[0];
    b[i] = r0[ds[i]];
    c[i] = r1[0];
    d[i] = r1[ds[i]];
  }
  for (int i = 0; i < n; ++i) {
    const auto fa = static_cast<float>(a[i]);
    const auto fc = static_cast<float>(c[i]);
    const auto fws = static_cast<float>(ws[i]);
    const float top = fa * 256.0f + fws * (static_cast<float>(b[i]) - fa);
    const float bottom = fc * 256.0f + fws * (static_cast<float>(d[i]) - fc);
    out[i] = top * 256.0f + static_cast<float>(wt[i]) * (bottom - top);
  }
}

// Shades pixels [begin, end) of a chunk that all have one key.
MAPLESS_KERNEL void ShadeSegment(const Prepared& p, const RunValues& v, int begin, int end,
                                 std::uint8_t* out) {
  constexpr float kInv16 = 1.0f / 65536.0f;
  const std::int32_t key = v.key[begin];
  const int n = end - begin;
  if (key == kKeyCoarsest) {
    const std::uint8_t value =
        RoundToByte(p.shade * static_cast<float>(p.levels[p.max_level].data[0]));
    std::fill(out + begin, out + end, value);
    return;
  }
  const float scale = p.shade * kInv16;
  const int l0 = key == kKeyFinest ? 0 : key;
  float v0[kChunk];
  SampleLevel(p.levels[l0], l0, v.s + begin, v.t + begin, n, v0);
  if (key == kKeyFinest) {
    for (int i = 0; i < n; ++i) out[begin + i] = RoundToByte(scale * v0[i]);
    return;
  }
  float v1[kChunk];
  SampleLevel(p.levels[l0 + 1], l0 + 1, v.s + begin, v.t + begin, n, v1);
  const float* w = v.w + begin;
  for (int i = 0; i < n; ++i) {
    out[begin + i] = RoundToByte(scale * (v0[i] + w[i] * (v1[i] - v0[i])));
  }
}

// Shades up to kChunk pixels that see surface p; false if a texture coordinate does not fit the
// 32-bit arithmetic (the caller then uses ShadeHit).
MAPLESS_KERNEL bool ShadeChunk(const Prepared& p, const float* alpha, const float* beta,
                               const float* nd, int n, float lod_slope, std::uint8_t* out) {
  RunValues v;
  std::int32_t misfits = 0;
  const float max_level = static_cast<float>(p.max_level);
  for (int i = 0; i < n; ++i) {
    // ShadeHit's fixed-point coordinates and mip level, from the same functions.
    const float fs = TexelTimes256(alpha[i], p.s_scale);
    const float ft = TexelTimes256(beta[i], p.t_scale);
    misfits += static_cast<std::int32_t>(std::abs(fs) >= 2147483648.0f);
    misfits += static_cast<std::int32_t>(std::abs(ft) >= 2147483648.0f);
    v.s[i] = static_cast<std::int32_t>(fs);
    v.t[i] = static_cast<std::int32_t>(ft);
    const float lod = MipLevel(p, nd[i], lod_slope);
    // max(lod, 0) as a select: GCC leaves the loop scalar with std::max.
    const auto l0 = static_cast<std::int32_t>(Select(lod > 0.0f, lod, 0.0f));
    v.w[i] = lod - static_cast<float>(l0);
    // ShadeHit's order of the cases: lod <= 0 first.
    const std::int32_t key = Select(lod <= 0.0f, kKeyFinest, l0);
    v.key[i] = Select((lod > 0.0f) & (lod >= max_level), kKeyCoarsest, key);
  }
  if (misfits != 0) return false;
  int begin = 0;
  while (begin < n) {
    int end = begin + 1;
    while (end < n && v.key[end] == v.key[begin]) ++end;
    ShadeSegment(p, v, begin, end, out);
    begin = end;
  }
  return true;
}

}  // namespace

MAPLESS_KERNEL void ShadeImage(const std::vector<Prepared>& prepared, const Buffers& buf,
                               const std::vector<float>& yd, const SkyRamp& sky, float lod_slope,
                               cv::Mat* image) {
  const int w = image->cols;
  for (int y = 0; y < image->rows; ++y) {
    std::uint8_t* out = image->ptr<std::uint8_t>(y);
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    const std::int32_t* id = buf.id.data() + row;
    int x = 0;
    while (x < w) {
      // A run of pixels that see the same surface (or the sky), at most a chunk long.
      const std::int32_t run_id = id[x];
      int end = x + 1;
      const int limit = std::min(w, x + kChunk);
      while (end < limit && id[end] == run_id) ++end;
      if (run_id < 0) {
        std::fill(out + x, out + end, RoundToByte(sky(yd[static_cast<std::size_t>(y)])));
        x = end;
        continue;
      }
      const Prepared& p = prepared[static_cast<std::size_t>(run_id)];
      const std::size_t i = row + static_cast<std::size_t>(x);
      if (!ShadeChunk(p, buf.alpha.data() + i, buf.beta.data() + i, buf.nd.data() + i, end - x,
                      lod_slope, out + x)) {
        for (int k = x; k < end; ++k) {
          const std::size_t j = row + static_cast<std::size_t>(k);
          out[k] = cv::saturate_cast<std::uint8_t>(
              ShadeHit(p, Hit{buf.depth[j], buf.alpha[j], buf.beta[j], buf.nd[j]}, lod_slope));
        }
      }
      x = end;
    }
  }
}

}  // namespace mapless::sim::raster::MAPLESS_KERNEL_NS

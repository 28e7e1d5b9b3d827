// The paper's dense pyramidal Lucas-Kanade (Ohnishi & Imiya, Appendix A).
//
// Each level: the first image's gradients and its window-averaged structure tensor once, then per
// warping iteration the second image warped by the current flow, the window-averaged mismatch and
// the 2x2 systems solved for every pixel. The Sobel filters and the expansion are OpenCV's, and so
// are the box filters on a CPU without AVX2. The warp (with cv::remap's sampling), the products and
// the solve are loops of our own on vectors of pixels, fused so that no image is made only to be
// read once; on a CPU with AVX2 they and the box filters (with cv::boxFilter's arithmetic) run in
// an AVX2 build (dense_lk_avx2.cc). The flow is bit for bit that of the plain composition of
// OpenCV calls (`DenseLkKernelsTest.IsThePlainCompositionBitForBit`), with either build.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "mapless/core/cpu.h"
#include "mapless/flow/dense_lk_kernels.h"
#include "mapless/flow/flow.h"

namespace mapless::flow {
namespace {

using dense_lk::kInterBits;
using dense_lk::kInterTab;
using dense_lk::SolvePixel;
using dense_lk::SolveRow;
using dense_lk::WarpPixel;
using dense_lk::WarpRow;
#if MAPLESS_DENSE_LK_AVX2
using dense_lk::BoxFilterAvx2;
using dense_lk::SolveLanesAvx2;
using dense_lk::WarpLanesAvx2;
#endif

std::atomic<bool> force_baseline{false};

// The AVX2 build of the vector loops on a CPU that has AVX2, unless a test asked for the baseline.
bool Avx2() {
  return MAPLESS_DENSE_LK_AVX2 && CpuHasAvx2() && !force_baseline.load(std::memory_order_relaxed);
}

// The paper's pyramid of `grey` into *levels[0], *levels[1], ...: level 0 the image as float, each
// next one smoothed and subsampled; stops before a level would be made from one smaller than
// 8 px. Returns how many levels were made.
int PyramidInto(const cv::Mat& grey, const std::vector<cv::Mat*>& levels, cv::Mat* smooth) {
  grey.convertTo(*levels[0], CV_32F);
  const cv::Mat kernel = (cv::Mat_<float>(1, 3) << 0.25f, 0.5f, 0.25f);
  std::size_t count = 1;
  for (; count < levels.size(); ++count) {
    const cv::Mat& prev = *levels[count - 1];
    if (prev.cols < 8 || prev.rows < 8) break;
    cv::sepFilter2D(prev, *smooth, CV_32F, kernel, kernel, cv::Point(-1, -1), 0.0,
                    cv::BORDER_REFLECT101);
    cv::Mat& down = *levels[count];
    down.create((prev.rows + 1) / 2, (prev.cols + 1) / 2, CV_32F);
    for (int y = 0; y < down.rows; ++y) {
      const float* src = smooth->ptr<float>(2 * y);
      auto* dst = down.ptr<float>(y);
      for (int x = 0; x < down.cols; ++x) dst[x] = src[2 * x];
    }
  }
  return static_cast<int>(count);
}

// out1 = a * a, out2 = a * b, out3 = b * b, element-wise.
void TensorProducts(const cv::Mat& a, const cv::Mat& b, cv::Mat* out1, cv::Mat* out2,
                    cv::Mat* out3) {
  out1->create(a.size(), CV_32F);
  out2->create(a.size(), CV_32F);
  out3->create(a.size(), CV_32F);
  for (int y = 0; y < a.rows; ++y) {
    const float* pa = a.ptr<float>(y);
    const float* pb = b.ptr<float>(y);
    auto* o1 = out1->ptr<float>(y);
    auto* o2 = out2->ptr<float>(y);
    auto* o3 = out3->ptr<float>(y);
    for (int x = 0; x < a.cols; ++x) {
      o1[x] = pa[x] * pa[x];
      o2[x] = pa[x] * pb[x];
      o3[x] = pb[x] * pb[x];
    }
  }
}

#if CV_SIMD
// WarpPixel on the row's pixels in whole vectors (returns where it stopped). A vector whose four
// taps all lie inside the image (remap's own fast path) is done lane by lane with the same
// arithmetic: v_round is cvRound, no clipping or saturation is needed inside, the tap offsets are
// exact in float (checked by the caller: the image has fewer than 2^24 elements), and each lane's
// two taps in a row are one 8-byte copy. Any other vector goes pixel by pixel through WarpPixel.
int WarpLanes(const cv::Mat& i1, const WarpRow& r) {
  constexpr int kLanes = cv::v_float32::nlanes;
  const cv::v_float32 tab = cv::vx_setall_f32(kInterTab);
  const cv::v_float32 step = cv::vx_setall_f32(1.f / kInterTab);
  const cv::v_float32 one = cv::vx_setall_f32(1.f);
  const cv::v_float32 row = cv::vx_setall_f32(static_cast<float>(r.y));
  const cv::v_float32 stride = cv::vx_setall_f32(static_cast<float>(i1.step1()));
  const cv::v_int32 mask = cv::vx_setall_s32(kInterTab - 1);
  const cv::v_int32 minus_one = cv::vx_setall_s32(-1);
  const cv::v_int32 last_x = cv::vx_setall_s32(i1.cols - 1);  // cx < last_x: cx + 1 is inside
  const cv::v_int32 last_y = cv::vx_setall_s32(i1.rows - 1);
  const float* top = i1.ptr<float>();
  const float* bottom = top + i1.step1();
  int lane[kLanes];
  for (int k = 0; k < kLanes; ++k) lane[k] = k;
  const cv::v_int32 iota = cv::vx_load(lane);
  int offset[kLanes];
  float taps[2 * kLanes];
  int x = 0;
  for (; x + kLanes <= i1.cols; x += kLanes) {
    cv::v_float32 u, v;
    cv::v_load_deinterleave(r.flow + 2 * x, u, v);
    const cv::v_int32 sx = cv::v_round((cv::v_cvt_f32(cv::vx_setall_s32(x) + iota) + u) * tab);
    const cv::v_int32 sy = cv::v_round((row + v) * tab);
    const cv::v_int32 cx = sx >> kInterBits;
    const cv::v_int32 cy = sy >> kInterBits;
    if (!cv::v_check_all((cx > minus_one) & (cx < last_x) & (cy > minus_one) & (cy < last_y))) {
      for (int k = x; k < x + kLanes; ++k) WarpPixel(i1, r, k);
      continue;
    }
    cv::v_store(offset, cv::v_round(cv::v_cvt_f32(cy) * stride + cv::v_cvt_f32(cx)));
    // Each lane's two taps in a row, as one 8-byte copy (cv::v_lut_pairs would read them as a
    // misaligned int64).
    cv::v_float32 t0, t1, b0, b1;
    for (int k = 0; k < kLanes; ++k) std::memcpy(taps + 2 * k, top + offset[k], 2 * sizeof(float));
    cv::v_load_deinterleave(taps, t0, t1);
    for (int k = 0; k < kLanes; ++k)
      std::memcpy(taps + 2 * k, bottom + offset[k], 2 * sizeof(float));
    cv::v_load_deinterleave(taps, b0, b1);
    const cv::v_float32 ax = cv::v_cvt_f32(sx & mask) * step;
    const cv::v_float32 ay = cv::v_cvt_f32(sy & mask) * step;
    const cv::v_float32 warped = t0 * ((one - ay) * (one - ax)) + t1 * ((one - ay) * ax) +
                                 b0 * (ay * (one - ax)) + b1 * (ay * ax);
    const cv::v_float32 it = warped - cv::vx_load(r.i0 + x);
    cv::v_store(r.out1 + x, cv::vx_load(r.ix + x) * it);
    cv::v_store(r.out2 + x, cv::vx_load(r.iy + x) * it);
  }
  return x;
}
#endif

// The second image warped by the flow, minus the first, times the gradients: out1 = ix * it,
// out2 = iy * it with it = I1((x, y) + flow) - I0(x, y), the mismatch before the window average,
// I1 sampled as cv::remap samples it (WarpPixel). One pass instead of a map, a remap and two
// products.
void WarpedMismatch(const cv::Mat& flow, const cv::Mat& i1, const cv::Mat& i0, const cv::Mat& ix,
                    const cv::Mat& iy, cv::Mat* out1, cv::Mat* out2) {
  out1->create(i0.size(), CV_32F);
  out2->create(i0.size(), CV_32F);
  // Tap offsets are computed in float in the vector path: exact below 2^24.
  const bool lanes = static_cast<double>(i1.rows) * static_cast<double>(i1.step1()) < (1 << 24);
  for (int y = 0; y < i0.rows; ++y) {
    const WarpRow r{y,
                    flow.ptr<float>(y),
                    i0.ptr<float>(y),
                    ix.ptr<float>(y),
                    iy.ptr<float>(y),
                    out1->ptr<float>(y),
                    out2->ptr<float>(y)};
    int x = 0;
#if MAPLESS_DENSE_LK_AVX2
    if (lanes && Avx2()) x = WarpLanesAvx2(i1, r);
#endif
#if CV_SIMD
    if (lanes && x == 0) x = WarpLanes(i1, r);
#endif
    for (; x < i0.cols; ++x) WarpPixel(i1, r, x);
  }
}

#if CV_SIMD
// SolvePixel on a vector of pixels with OpenCV's universal intrinsics (SSE2 or NEON): the
// same IEEE operations in the same order lane by lane, std::max and std::clamp as selects, so the
// same bits. The scalar loop cannot vectorise: std::sqrt may set errno.
inline void SolveVector(const cv::v_float32& s11, const cv::v_float32& s12,
                        const cv::v_float32& s22, const cv::v_float32& q1, const cv::v_float32& q2,
                        const cv::v_float32& min_eigen, float* uv) {
  const cv::v_float32 zero = cv::vx_setzero_f32();
  const cv::v_float32 one = cv::vx_setall_f32(1.f);
  const cv::v_float32 minus_one = cv::vx_setall_f32(-1.f);
  const cv::v_float32 det = s11 * s22 - s12 * s12;
  const cv::v_float32 tr = cv::vx_setall_f32(0.5f) * (s11 + s22);
  const cv::v_float32 disc = tr * tr - det;
  const cv::v_float32 min_eig = tr - cv::v_sqrt(cv::v_select(zero < disc, disc, zero));
  const cv::v_float32 skip = (min_eig < min_eigen) | (det <= zero);
  const cv::v_float32 inv = one / det;
  cv::v_float32 du = (s12 * q2 - s22 * q1) * inv;
  cv::v_float32 dv = (s12 * q1 - s11 * q2) * inv;
  du = cv::v_select(du < minus_one, minus_one, cv::v_select(one < du, one, du));
  dv = cv::v_select(dv < minus_one, minus_one, cv::v_select(one < dv, one, dv));
  cv::v_float32 u, v;
  cv::v_load_deinterleave(uv, u, v);
  cv::v_store_interleave(uv, cv::v_select(skip, u, u + du), cv::v_select(skip, v, v + dv));
}
#endif

#if CV_SIMD
int SolveLanes(const SolveRow& r, int cols) {
  const cv::v_float32 min_eigen = cv::vx_setall_f32(r.min_eigen);
  int x = 0;
  for (; x + cv::v_float32::nlanes <= cols; x += cv::v_float32::nlanes) {
    SolveVector(cv::vx_load(r.a11 + x), cv::vx_load(r.a12 + x), cv::vx_load(r.a22 + x),
                cv::vx_load(r.b1 + x), cv::vx_load(r.b2 + x), min_eigen, r.flow + 2 * x);
  }
  return x;
}
#endif

void SolveAndAdd(const cv::Mat& a11, const cv::Mat& a12, const cv::Mat& a22, const cv::Mat& b1,
                 const cv::Mat& b2, float min_eigen, cv::Mat* flow) {
  for (int y = 0; y < flow->rows; ++y) {
    const SolveRow r{a11.ptr<float>(y), a12.ptr<float>(y),   a22.ptr<float>(y), b1.ptr<float>(y),
                     b2.ptr<float>(y),  flow->ptr<float>(y), min_eigen};
    int x = 0;
#if MAPLESS_DENSE_LK_AVX2
    if (Avx2()) x = SolveLanesAvx2(r, flow->cols);
#endif
#if CV_SIMD
    if (x == 0) x = SolveLanes(r, flow->cols);
#endif
    for (; x < flow->cols; ++x) {
      SolvePixel(r.a11[x], r.a12[x], r.a22[x], r.b1[x], r.b2[x], min_eigen, &r.flow[2 * x],
                 &r.flow[2 * x + 1]);
    }
  }
}

// cv::boxFilter(src, *dst, CV_32F, cv::Size(k, k)), by the AVX2 build of its arithmetic where
// there is one (the same bits, BoxFilterAvx2).
void WindowMean(const cv::Mat& src, int k, std::vector<double>* work, cv::Mat* dst) {
#if MAPLESS_DENSE_LK_AVX2
  if (Avx2() && (k == 3 || k == 5)) {
    BoxFilterAvx2(src, k, work, dst);
    return;
  }
#endif
  static_cast<void>(work);
  cv::boxFilter(src, *dst, CV_32F, cv::Size(k, k));
}

// One pyramid level's images.
struct Level {
  cv::Mat i0, i1;            // the two images at this level (CV_32F)
  cv::Mat ix, iy;            // the first image's gradients
  cv::Mat a11, a12, a22;     // the window-averaged structure tensor
  cv::Mat b1, b2;            // the window-averaged mismatch vector
  cv::Mat p1, p2, p3;        // products before the window average
  cv::Mat flow, median;      // this level's flow (CV_32FC2) and its median
  std::vector<double> sums;  // the box filter's
};

// Both pyramids into `levels`; returns how many levels were made.
int BuildPyramids(const cv::Mat& a, const cv::Mat& b, std::vector<Level>* levels) {
  std::vector<cv::Mat*> first, second;
  for (Level& level : *levels) {
    first.push_back(&level.i0);
    second.push_back(&level.i1);
  }
  cv::Mat smooth;
  const int count = PyramidInto(a, first, &smooth);
  PyramidInto(b, second, &smooth);
  return count;
}

// The level's flow refined by the options' warping iterations, then its median.
void SolveLevel(const DenseLkOptions& options, Level* level) {
  cv::Sobel(level->i0, level->ix, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REFLECT101);
  cv::Sobel(level->i0, level->iy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REFLECT101);
  TensorProducts(level->ix, level->iy, &level->p1, &level->p2, &level->p3);
  WindowMean(level->p1, options.window, &level->sums, &level->a11);
  WindowMean(level->p2, options.window, &level->sums, &level->a12);
  WindowMean(level->p3, options.window, &level->sums, &level->a22);
  for (int it = 0; it < options.iterations; ++it) {
    WarpedMismatch(level->flow, level->i1, level->i0, level->ix, level->iy, &level->p1, &level->p2);
    WindowMean(level->p1, options.window, &level->sums, &level->b1);
    WindowMean(level->p2, options.window, &level->sums, &level->b2);
    SolveAndAdd(level->a11, level->a12, level->a22, level->b1, level->b2,
                static_cast<float>(options.min_eigen), &level->flow);
  }
  if (options.median) {
    cv::medianBlur(level->flow, level->median, 3);
    std::swap(level->flow, level->median);
  }
}

}  // namespace

std::vector<cv::Mat> BuildPyramid(const cv::Mat& grey, int levels) {
  std::vector<cv::Mat> pyramid(static_cast<std::size_t>(std::max(levels, 1)));
  std::vector<cv::Mat*> out;
  for (cv::Mat& level : pyramid) out.push_back(&level);
  cv::Mat smooth;
  pyramid.resize(static_cast<std::size_t>(PyramidInto(grey, out, &smooth)));
  return pyramid;
}

const char* DenseLkKernels() { return Avx2() ? "avx2" : "baseline"; }

void UseBaselineDenseLkKernels(bool baseline) { force_baseline.store(baseline); }

cv::Mat DenseLucasKanade(const cv::Mat& first, const cv::Mat& second, const DenseLkOptions& options,
                         std::vector<cv::Mat>* level_flows) {
  options.Validate();
  const auto [a, b] = GreyPair(first, second, "DenseLucasKanade");
  std::vector<Level> levels(static_cast<std::size_t>(options.levels));
  const int count = BuildPyramids(a, b, &levels);
  if (level_flows != nullptr) level_flows->clear();
  for (int l = count - 1; l >= 0; --l) {
    Level& level = levels[static_cast<std::size_t>(l)];
    if (l == count - 1) {
      level.flow = cv::Mat::zeros(level.i0.size(), CV_32FC2);
    } else {
      // Expand the coarser flow to this level: twice the size, twice the vectors.
      cv::resize(levels[static_cast<std::size_t>(l) + 1].flow, level.flow, level.i0.size(), 0, 0,
                 cv::INTER_LINEAR);
      level.flow.convertTo(level.flow, -1, 2.0);
    }
    SolveLevel(options, &level);
    if (level_flows != nullptr) level_flows->insert(level_flows->begin(), level.flow.clone());
  }
  return levels[0].flow;
}

}  // namespace mapless::flow

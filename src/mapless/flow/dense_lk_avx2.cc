// The dense Lucas-Kanade's warp, solve and box filter with AVX2 (dense_lk_kernels.h).
//
// Only these functions carry the AVX2 target attribute; everything they call that is not
// inlined stays baseline code, so no out-of-line copy the linker might share needs AVX2. AVX2 does
// not include FMA: every multiply and add rounds on its own, as in the baseline loops, and the
// flow is the same bit for bit (`DenseLucasKanade.Avx2KernelsGiveTheBaselineFlow`).
#include "mapless/flow/dense_lk_kernels.h"

#if MAPLESS_DENSE_LK_AVX2

#include <immintrin.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <vector>

#define MAPLESS_AVX2 __attribute__((target("avx2")))

namespace mapless::flow::dense_lk {
namespace {

// Eight (u, v) pairs from `uv` as u0..u7 and v0..v7.
MAPLESS_AVX2 inline void LoadDeinterleaved(const float* uv, __m256* u, __m256* v) {
  const __m256 a = _mm256_loadu_ps(uv);      // u0 v0 u1 v1 | u2 v2 u3 v3
  const __m256 b = _mm256_loadu_ps(uv + 8);  // u4 v4 u5 v5 | u6 v6 u7 v7
  // u0 u1 u4 u5 | u2 u3 u6 u7, then the 64-bit quarters back in order.
  const __m256 us = _mm256_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0));
  const __m256 vs = _mm256_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1));
  *u = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(us), _MM_SHUFFLE(3, 1, 2, 0)));
  *v = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(vs), _MM_SHUFFLE(3, 1, 2, 0)));
}

MAPLESS_AVX2 inline void StoreInterleaved(float* uv, __m256 u, __m256 v) {
  const __m256 lo = _mm256_unpacklo_ps(u, v);  // u0 v0 u1 v1 | u4 v4 u5 v5
  const __m256 hi = _mm256_unpackhi_ps(u, v);  // u2 v2 u3 v3 | u6 v6 u7 v7
  _mm256_storeu_ps(uv, _mm256_permute2f128_ps(lo, hi, 0x20));
  _mm256_storeu_ps(uv + 8, _mm256_permute2f128_ps(lo, hi, 0x31));
}

// a < b as a lane mask (false when either is NaN, as the scalar comparison).
MAPLESS_AVX2 inline __m256 Less(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }

// mask ? a : b
MAPLESS_AVX2 inline __m256 Select(__m256 mask, __m256 a, __m256 b) {
  return _mm256_blendv_ps(b, a, mask);
}

// std::clamp(v, -1, 1)
MAPLESS_AVX2 inline __m256 ClampToOne(__m256 v) {
  const __m256 one = _mm256_set1_ps(1.f);
  const __m256 minus_one = _mm256_set1_ps(-1.f);
  return Select(Less(v, minus_one), minus_one, Select(Less(one, v), one, v));
}

}  // namespace

MAPLESS_AVX2 int WarpLanesAvx2(const cv::Mat& i1, const WarpRow& r) {
  const __m256 tab = _mm256_set1_ps(static_cast<float>(kInterTab));
  const __m256 step = _mm256_set1_ps(1.f / kInterTab);
  const __m256 one = _mm256_set1_ps(1.f);
  const __m256 row = _mm256_set1_ps(static_cast<float>(r.y));
  const __m256i mask = _mm256_set1_epi32(kInterTab - 1);
  const __m256i minus_one = _mm256_set1_epi32(-1);
  const __m256i last_x = _mm256_set1_epi32(i1.cols - 1);  // cx < last_x: cx + 1 is inside
  const __m256i last_y = _mm256_set1_epi32(i1.rows - 1);
  const __m256i stride = _mm256_set1_epi32(static_cast<int>(i1.step1()));
  const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const float* top = i1.ptr<float>();
  const float* bottom = top + i1.step1();
  int x = 0;
  for (; x + 8 <= i1.cols; x += 8) {
    __m256 u, v;
    LoadDeinterleaved(r.flow + 2 * x, &u, &v);
    const __m256 px = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_set1_epi32(x), iota));
    const __m256i sx = _mm256_cvtps_epi32(_mm256_mul_ps(_mm256_add_ps(px, u), tab));
    const __m256i sy = _mm256_cvtps_epi32(_mm256_mul_ps(_mm256_add_ps(row, v), tab));
    const __m256i cx = _mm256_srai_epi32(sx, kInterBits);
    const __m256i cy = _mm256_srai_epi32(sy, kInterBits);
    const __m256i inside = _mm256_and_si256(
        _mm256_and_si256(_mm256_cmpgt_epi32(cx, minus_one), _mm256_cmpgt_epi32(last_x, cx)),
        _mm256_and_si256(_mm256_cmpgt_epi32(cy, minus_one), _mm256_cmpgt_epi32(last_y, cy)));
    if (_mm256_movemask_epi8(inside) != -1) {
      for (int k = x; k < x + 8; ++k) WarpPixel(i1, r, k);
      continue;
    }
    const __m256i offset = _mm256_add_epi32(_mm256_mullo_epi32(cy, stride), cx);
    const __m256 t0 = _mm256_i32gather_ps(top, offset, 4);
    const __m256 t1 = _mm256_i32gather_ps(top + 1, offset, 4);
    const __m256 b0 = _mm256_i32gather_ps(bottom, offset, 4);
    const __m256 b1 = _mm256_i32gather_ps(bottom + 1, offset, 4);
    const __m256 ax = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_and_si256(sx, mask)), step);
    const __m256 ay = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_and_si256(sy, mask)), step);
    const __m256 wy0 = _mm256_sub_ps(one, ay);
    const __m256 wx0 = _mm256_sub_ps(one, ax);
    __m256 warped = _mm256_mul_ps(t0, _mm256_mul_ps(wy0, wx0));
    warped = _mm256_add_ps(warped, _mm256_mul_ps(t1, _mm256_mul_ps(wy0, ax)));
    warped = _mm256_add_ps(warped, _mm256_mul_ps(b0, _mm256_mul_ps(ay, wx0)));
    warped = _mm256_add_ps(warped, _mm256_mul_ps(b1, _mm256_mul_ps(ay, ax)));
    const __m256 it = _mm256_sub_ps(warped, _mm256_loadu_ps(r.i0 + x));
    _mm256_storeu_ps(r.out1 + x, _mm256_mul_ps(_mm256_loadu_ps(r.ix + x), it));
    _mm256_storeu_ps(r.out2 + x, _mm256_mul_ps(_mm256_loadu_ps(r.iy + x), it));
  }
  return x;
}

MAPLESS_AVX2 int SolveLanesAvx2(const SolveRow& r, int cols) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 half = _mm256_set1_ps(0.5f);
  const __m256 one = _mm256_set1_ps(1.f);
  const __m256 min_eigen = _mm256_set1_ps(r.min_eigen);
  int x = 0;
  for (; x + 8 <= cols; x += 8) {
    const __m256 s11 = _mm256_loadu_ps(r.a11 + x);
    const __m256 s12 = _mm256_loadu_ps(r.a12 + x);
    const __m256 s22 = _mm256_loadu_ps(r.a22 + x);
    const __m256 q1 = _mm256_loadu_ps(r.b1 + x);
    const __m256 q2 = _mm256_loadu_ps(r.b2 + x);
    const __m256 det = _mm256_sub_ps(_mm256_mul_ps(s11, s22), _mm256_mul_ps(s12, s12));
    const __m256 tr = _mm256_mul_ps(half, _mm256_add_ps(s11, s22));
    const __m256 disc = _mm256_sub_ps(_mm256_mul_ps(tr, tr), det);
    const __m256 min_eig = _mm256_sub_ps(tr, _mm256_sqrt_ps(Select(Less(zero, disc), disc, zero)));
    const __m256 skip =
        _mm256_or_ps(Less(min_eig, min_eigen), _mm256_cmp_ps(det, zero, _CMP_LE_OQ));
    const __m256 inv = _mm256_div_ps(one, det);
    const __m256 du = ClampToOne(
        _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(s12, q2), _mm256_mul_ps(s22, q1)), inv));
    const __m256 dv = ClampToOne(
        _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(s12, q1), _mm256_mul_ps(s11, q2)), inv));
    __m256 u, v;
    LoadDeinterleaved(r.flow + 2 * x, &u, &v);
    StoreInterleaved(r.flow + 2 * x, Select(skip, u, _mm256_add_ps(u, du)),
                     Select(skip, v, _mm256_add_ps(v, dv)));
  }
  return x;
}

namespace {

// Row `y`'s k-wide window sums (with the border reflected) into `sums`, each added left to right in
// double: OpenCV's RowSum for k 3 and 5.
MAPLESS_AVX2 void RowWindowSums(const float* s, int width, int k, double* sums) {
  const int r = k / 2;
  const auto border_sum = [&](int x) {
    double sum = s[cv::borderInterpolate(x - r, width, cv::BORDER_REFLECT_101)];
    for (int j = 1; j < k; ++j)
      sum +=
          static_cast<double>(s[cv::borderInterpolate(x - r + j, width, cv::BORDER_REFLECT_101)]);
    return sum;
  };
  int x = 0;
  for (; x < std::min(r, width); ++x) sums[x] = border_sum(x);
  for (; x + 4 <= width - r; x += 4) {
    __m256d sum = _mm256_cvtps_pd(_mm_loadu_ps(s + x - r));
    for (int j = 1; j < k; ++j)
      sum = _mm256_add_pd(sum, _mm256_cvtps_pd(_mm_loadu_ps(s + x - r + j)));
    _mm256_storeu_pd(sums + x, sum);
  }
  for (; x < width; ++x) sums[x] = border_sum(x);
}

}  // namespace

MAPLESS_AVX2 void BoxFilterAvx2(const cv::Mat& src, int k, std::vector<double>* work,
                                cv::Mat* dst) {
  const int width = src.cols, height = src.rows, r = k / 2;
  dst->create(src.size(), CV_32F);
  const auto w = static_cast<std::size_t>(width);
  work->assign(w * static_cast<std::size_t>(k + 1), 0.0);
  double* column = work->data();  // the sliding column sums, then k rows of window sums
  const auto ring = [&](int extended_row) {
    return column + w * static_cast<std::size_t>(1 + extended_row % k);
  };
  // Extended row j is source row j - r, reflected at the borders.
  const auto row_sums = [&](int j) {
    const int y = cv::borderInterpolate(j - r, height, cv::BORDER_REFLECT_101);
    RowWindowSums(src.ptr<float>(y), width, k, ring(j));
  };
  for (int j = 0; j < k - 1; ++j) {
    row_sums(j);
    const double* s = ring(j);
    for (int x = 0; x < width; ++x) column[x] += s[x];
  }
  const double scale = 1. / (k * k);
  const __m256d scale_v = _mm256_set1_pd(scale);
  for (int y = 0; y < height; ++y) {
    row_sums(y + k - 1);
    const double* entering = ring(y + k - 1);
    const double* leaving = ring(y);
    auto* out = dst->ptr<float>(y);
    int x = 0;
    for (; x + 4 <= width; x += 4) {
      const __m256d s = _mm256_add_pd(_mm256_loadu_pd(column + x), _mm256_loadu_pd(entering + x));
      _mm_storeu_ps(out + x, _mm256_cvtpd_ps(_mm256_mul_pd(s, scale_v)));
      _mm256_storeu_pd(column + x, _mm256_sub_pd(s, _mm256_loadu_pd(leaving + x)));
    }
    for (; x < width; ++x) {
      const double s = column[x] + entering[x];
      out[x] = static_cast<float>(s * scale);
      column[x] = s - leaving[x];
    }
  }
}

}  // namespace mapless::flow::dense_lk

#endif  // MAPLESS_DENSE_LK_AVX2

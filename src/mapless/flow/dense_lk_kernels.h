// The dense Lucas-Kanade's per-pixel steps (dense_lk.cc), shared by its baseline vector loops and
// their AVX2 build (dense_lk_avx2.cc, x86-64 only, chosen at run time).
#pragma once

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__))
#define MAPLESS_DENSE_LK_AVX2 1
#else
#define MAPLESS_DENSE_LK_AVX2 0
#endif

namespace mapless::flow::dense_lk {

constexpr int kInterBits = 5;  // cv::INTER_BITS: remap rounds positions to 1/32 px
constexpr int kInterTab = 1 << kInterBits;

// Index x clamped to [0, size): cv::remap's BORDER_REPLICATE.
inline int Clip(int x, int size) { return x >= 0 ? (x < size ? x : size - 1) : 0; }

// The rows the warp reads and writes (one row of each image).
struct WarpRow {
  int y;
  const float* flow;  // (u, v) interleaved
  const float* i0;    // the first image
  const float* ix;    // its gradients
  const float* iy;
  float* out1;  // ix * it
  float* out2;  // iy * it
};

// Pixel x of the warp: I1 sampled exactly as cv::remap samples a CV_32F image with a CV_32FC2 map,
// INTER_LINEAR and BORDER_REPLICATE: the position rounded to 1/32 px, saturated to 16 bits, the
// four weights products of multiples of 1/32 (exact in float), summed in remap's order.
inline void WarpPixel(const cv::Mat& i1, const WarpRow& r, int x) {
  constexpr float kStep = 1.f / kInterTab;
  const auto tab = static_cast<float>(kInterTab);
  const int sx = cvRound((static_cast<float>(x) + r.flow[2 * x]) * tab);
  const int sy = cvRound((static_cast<float>(r.y) + r.flow[2 * x + 1]) * tab);
  const int cx = cv::saturate_cast<short>(sx >> kInterBits);
  const int cy = cv::saturate_cast<short>(sy >> kInterBits);
  const float ax = static_cast<float>(sx & (kInterTab - 1)) * kStep;
  const float ay = static_cast<float>(sy & (kInterTab - 1)) * kStep;
  const float* r0 = i1.ptr<float>(Clip(cy, i1.rows));
  const float* r1 = i1.ptr<float>(Clip(cy + 1, i1.rows));
  const int x0 = Clip(cx, i1.cols), x1 = Clip(cx + 1, i1.cols);
  const float warped = r0[x0] * ((1.f - ay) * (1.f - ax)) + r0[x1] * ((1.f - ay) * ax) +
                       r1[x0] * (ay * (1.f - ax)) + r1[x1] * (ay * ax);
  const float it = warped - r.i0[x];
  r.out1[x] = r.ix[x] * it;
  r.out2[x] = r.iy[x] * it;
}

// One pixel's 2x2 system [s11 s12; s12 s22] d = -[q1; q2], d added to (u, v) unless the window is
// flat (the tensor's smaller eigenvalue below min_eigen, as OpenCV's LK rejects it) or singular.
inline void SolvePixel(float s11, float s12, float s22, float q1, float q2, float min_eigen,
                       float* u, float* v) {
  const float det = s11 * s22 - s12 * s12;
  const float tr = 0.5f * (s11 + s22);
  const float min_eig = tr - std::sqrt(std::max(0.f, tr * tr - det));
  if (min_eig < min_eigen || det <= 0.f) return;
  const float inv = 1.f / det;
  // One linearisation step is only valid for about a pixel: clamp it.
  *u += std::clamp((-s22 * q1 + s12 * q2) * inv, -1.f, 1.f);
  *v += std::clamp((s12 * q1 - s11 * q2) * inv, -1.f, 1.f);
}

// The rows the solve reads and writes.
struct SolveRow {
  const float* a11;  // the window-averaged tensor
  const float* a12;
  const float* a22;
  const float* b1;  // the window-averaged mismatch
  const float* b2;
  float* flow;  // (u, v) interleaved
  float min_eigen;
};

#if MAPLESS_DENSE_LK_AVX2
// WarpPixel and SolvePixel on the row's pixels in vectors of eight with AVX2, lane by lane the same
// operations (AVX2 has no FMA: nothing is fused), so the same bits as the baseline. Each returns
// the first pixel it left for the scalar tail. Only to be called on a CPU with AVX2.
int WarpLanesAvx2(const cv::Mat& i1, const WarpRow& r);
int SolveLanesAvx2(const SolveRow& r, int cols);

// cv::boxFilter(src, *dst, CV_32F, cv::Size(k, k)) for a CV_32F `src` and k 3 or 5 (normalised,
// anchored at the centre, BORDER_REFLECT_101), with the arithmetic of OpenCV 4.6's box filter for
// floats, so with its bits: each row's window sum in double added left to right (RowSum, its k 3
// and 5 case), the column sums slid down in double (ColumnSum<double, float>: add the entering
// row, scale by 1/k^2, round to float, subtract the leaving row). OpenCV's column pass is a
// scalar loop; here both passes run on four columns at a time. `work` holds the sums.
void BoxFilterAvx2(const cv::Mat& src, int k, std::vector<double>* work, cv::Mat* dst);
#endif

}  // namespace mapless::flow::dense_lk

#include "mapless/features/orb.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::features {

// OpenCV 4's scalar atan_f32, written out (orb.h).
float FastAtan2Degrees(float y, float x) {
  constexpr float kDegrees = static_cast<float>(180 / CV_PI);
  constexpr float p1 = 0.9997878412794807f * kDegrees;
  constexpr float p3 = -0.3258083974640975f * kDegrees;
  constexpr float p5 = 0.1555786518463281f * kDegrees;
  constexpr float p7 = -0.04432655554792128f * kDegrees;
  const float ax = std::abs(x);
  const float ay = std::abs(y);
  float a;
  if (ax >= ay) {
    const float c = ay / (ax + static_cast<float>(DBL_EPSILON));
    const float c2 = c * c;
    a = (((p7 * c2 + p5) * c2 + p3) * c2 + p1) * c;
  } else {
    const float c = ax / (ay + static_cast<float>(DBL_EPSILON));
    const float c2 = c * c;
    a = 90.f - (((p7 * c2 + p5) * c2 + p3) * c2 + p1) * c;
  }
  if (x < 0) a = 180.f - a;
  if (y < 0) a = 360.f - a;
  return a;
}

namespace {

constexpr int kEdge = 31;   // no keypoint closer than this to its level's edge (cv::ORB's default)
constexpr int kPatch = 31;  // orientation patch and descriptor tests (cv::ORB's default)
constexpr int kHalfPatch = kPatch / 2;
constexpr int kHarrisBlock = 7;
constexpr float kHarrisK = 0.04f;
constexpr int kDescriptorBytes = 32;
constexpr int kTests = 8 * kDescriptorBytes;
// FAST scores a corner from the 7x7 window around it, and its non-maximum suppression compares
// the 8 neighbours' scores: the kept corners (>= kEdge from the edge) see exactly what they see
// on the whole level when FAST runs on the level minus kEdge - 4 px all round.
constexpr int kFastMargin = kEdge - 4;
// A descriptor test reaches at most 13 * sqrt(2) ~ 18 px from its keypoint, so from kEdge - 18 =
// 13 px inside the level; the 7x7 blur needs 3 px more, still inside the level.
constexpr int kBlurMargin = 12;

// The test pairs, read off cv::ORB::compute: for a keypoint of angle 0 at the centre of a probe
// image, each bit compares the blurred image (cv::GaussianBlur as cv::ORB applies it, computed
// here too) at the pair's two offsets. Probes that vary along one axis only, a step edge at every
// position k, rising and falling, tell each pair's two offsets along that axis: exactly one pair
// of offsets fits every probe, unless the two are equal (then every equal pair fits). For those,
// a ramp along the other axis, dark where the first axis is below k, tells the common offset.
constexpr int kProbeSize = 64;
constexpr int kProbeCentre = 32;  // cv::ORB keeps keypoints >= 31 px from the image's edge
constexpr int kProbeReach = 15;   // offsets searched in [-15, 15] (ORB's are in [-13, 12])
constexpr int kStepRange = 19;    // edges at [-19, 19]: every pair's answer changes

struct Probe {
  cv::Mat blurred;
  std::vector<uchar> bits;  // the descriptor's kTests bits
  bool Fits(int t, const cv::Point& first, const cv::Point& second) const {
    const uchar b1 = blurred.at<uchar>(kProbeCentre + first.y, kProbeCentre + first.x);
    const uchar b2 = blurred.at<uchar>(kProbeCentre + second.y, kProbeCentre + second.x);
    return static_cast<uchar>(b1 < b2) == bits[static_cast<std::size_t>(t)];
  }
};

// One probe: the image value(u, v) at offset (u, v) from its centre, its descriptor's bits by
// cv::ORB::compute and its blurred image.
template <typename Value>
bool RunProbe(const cv::Ptr<cv::ORB>& orb, const Value& value, std::vector<Probe>* probes) {
  cv::Mat image(kProbeSize, kProbeSize, CV_8U);
  for (int y = 0; y < kProbeSize; ++y) {
    for (int x = 0; x < kProbeSize; ++x) {
      image.at<uchar>(y, x) =
          static_cast<uchar>(std::clamp(value(x - kProbeCentre, y - kProbeCentre), 0, 255));
    }
  }
  std::vector<cv::KeyPoint> kp{cv::KeyPoint(kProbeCentre, kProbeCentre, kPatch, 0.f, 0.f, 0)};
  cv::Mat descriptor;
  orb->compute(image, kp, descriptor);
  if (kp.size() != 1 || descriptor.rows != 1 || descriptor.cols != kDescriptorBytes ||
      descriptor.type() != CV_8U) {
    return false;
  }
  Probe p;
  cv::GaussianBlur(image, p.blurred, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
  for (int t = 0; t < kTests; ++t) {
    p.bits.push_back(static_cast<uchar>((descriptor.at<uchar>(0, t / 8) >> (t % 8)) & 1));
  }
  probes->push_back(std::move(p));
  return true;
}

cv::Point OnAxis(bool along_x, int offset) {
  return along_x ? cv::Point(offset, 0) : cv::Point(0, offset);
}
int& Coordinate(cv::Point* p, bool along_x) { return along_x ? p->x : p->y; }

// Each test's offsets along one axis; `same[t]` when they are equal (the offset then unknown).
bool ProbeAxis(const cv::Ptr<cv::ORB>& orb, bool along_x, std::vector<OrbTestPair>* pairs,
               std::vector<bool>* same) {
  std::vector<Probe> probes;
  for (const bool rising : {true, false}) {
    for (int k = -kStepRange; k <= kStepRange; ++k) {
      const auto step = [&](int u, int v) { return ((along_x ? u : v) >= k) == rising ? 255 : 0; };
      if (!RunProbe(orb, step, &probes)) return false;
    }
  }
  for (int t = 0; t < kTests; ++t) {
    int found = 0;
    bool all_equal = true;
    for (int u1 = -kProbeReach; u1 <= kProbeReach; ++u1) {
      for (int u2 = -kProbeReach; u2 <= kProbeReach; ++u2) {
        const bool fits = std::all_of(probes.begin(), probes.end(), [&](const Probe& p) {
          return p.Fits(t, OnAxis(along_x, u1), OnAxis(along_x, u2));
        });
        if (!fits) continue;
        ++found;
        all_equal = all_equal && u1 == u2;
        Coordinate(&(*pairs)[t].first, along_x) = u1;
        Coordinate(&(*pairs)[t].second, along_x) = u2;
      }
    }
    if (found == 0 || (found > 1 && !all_equal)) return false;
    (*same)[t] = found > 1;
  }
  return true;
}

// The common offset along one axis of the tests whose two points share it (their offsets along
// the other axis known and different).
bool ProbeSharedOffset(const cv::Ptr<cv::ORB>& orb, bool along_x, const std::vector<bool>& same,
                       std::vector<OrbTestPair>* pairs) {
  std::vector<Probe> probes;
  for (const int slope : {7, -7}) {
    for (int k = -kStepRange; k <= kStepRange; ++k) {
      const auto masked_ramp = [&](int u, int v) {
        return (along_x ? u : v) >= k ? 128 + slope * (along_x ? v : u) : 0;
      };
      if (!RunProbe(orb, masked_ramp, &probes)) return false;
    }
  }
  for (int t = 0; t < kTests; ++t) {
    if (!same[static_cast<std::size_t>(t)]) continue;
    OrbTestPair& pair = (*pairs)[static_cast<std::size_t>(t)];
    int found = 0;
    int offset = 0;
    for (int u = -kProbeReach; u <= kProbeReach; ++u) {
      cv::Point first = pair.first;
      cv::Point second = pair.second;
      Coordinate(&first, along_x) = u;
      Coordinate(&second, along_x) = u;
      if (std::all_of(probes.begin(), probes.end(),
                      [&](const Probe& p) { return p.Fits(t, first, second); })) {
        ++found;
        offset = u;
      }
    }
    if (found != 1) return false;
    Coordinate(&pair.first, along_x) = offset;
    Coordinate(&pair.second, along_x) = offset;
  }
  return true;
}

std::vector<OrbTestPair> ReadTestPairs() {
  const cv::Ptr<cv::ORB> orb =
      cv::ORB::create(1, 1.2f, 1, kEdge, 0, 2, cv::ORB::HARRIS_SCORE, kPatch);
  std::vector<OrbTestPair> pairs(kTests);
  std::vector<bool> same_x(kTests), same_y(kTests);
  if (!ProbeAxis(orb, true, &pairs, &same_x) || !ProbeAxis(orb, false, &pairs, &same_y)) return {};
  for (int t = 0; t < kTests; ++t) {
    if (same_x[static_cast<std::size_t>(t)] && same_y[static_cast<std::size_t>(t)]) return {};
  }
  if (!ProbeSharedOffset(orb, true, same_x, &pairs) ||
      !ProbeSharedOffset(orb, false, same_y, &pairs)) {
    return {};
  }
  return pairs;
}

// Half-widths of the circular orientation patch, row by row (v = 0..kHalfPatch), made symmetric
// in rows and columns as cv::ORB makes them.
std::vector<int> CircleHalfWidths() {
  std::vector<int> umax(kHalfPatch + 2);
  const int vmax = cvFloor(kHalfPatch * std::sqrt(2.f) / 2 + 1);
  const int vmin = cvCeil(kHalfPatch * std::sqrt(2.f) / 2);
  for (int v = 0; v <= vmax; ++v) {
    umax[v] = cvRound(std::sqrt(static_cast<double>(kHalfPatch) * kHalfPatch - v * v));
  }
  for (int v = kHalfPatch, v0 = 0; v >= vmin; --v) {
    while (umax[v0] == umax[v0 + 1]) ++v0;
    umax[v] = v0;
    ++v0;
  }
  return umax;
}

// Harris corner response over the 7x7 window at the keypoint (level coordinates), Sobel-like
// gradients, in cv::ORB's arithmetic (integer sums, the response in single precision).
float HarrisResponse(const cv::Mat& level, const cv::KeyPoint& kp) {
  const int r = kHarrisBlock / 2;
  const int step = static_cast<int>(level.step);
  const uchar* origin = level.ptr<uchar>(cvRound(kp.pt.y) - r) + (cvRound(kp.pt.x) - r);
  int a = 0, b = 0, c = 0;
  for (int i = 0; i < kHarrisBlock; ++i) {
    for (int j = 0; j < kHarrisBlock; ++j) {
      const uchar* p = origin + i * step + j;
      const int ix =
          (p[1] - p[-1]) * 2 + (p[-step + 1] - p[-step - 1]) + (p[step + 1] - p[step - 1]);
      const int iy =
          (p[step] - p[-step]) * 2 + (p[step - 1] - p[-step - 1]) + (p[step + 1] - p[-step + 1]);
      a += ix * ix;
      b += iy * iy;
      c += ix * iy;
    }
  }
  const float scale = 1.f / ((1 << 2) * kHarrisBlock * 255.f);
  const float scale4 = scale * scale * scale * scale;
  return (static_cast<float>(a) * b - static_cast<float>(c) * c -
          kHarrisK * (static_cast<float>(a) + b) * (static_cast<float>(a) + b)) *
         scale4;
}

// Orientation by the intensity centroid of the circular patch (degrees, as cv::fastAtan2).
float CentroidAngle(const cv::Mat& level, const cv::KeyPoint& kp, const std::vector<int>& umax) {
  const int step = static_cast<int>(level.step);
  const uchar* centre = level.ptr<uchar>(cvRound(kp.pt.y)) + cvRound(kp.pt.x);
  int m01 = 0, m10 = 0;
  for (int u = -kHalfPatch; u <= kHalfPatch; ++u) m10 += u * centre[u];
  for (int v = 1; v <= kHalfPatch; ++v) {
    int v_sum = 0;
    const int d = umax[v];
    for (int u = -d; u <= d; ++u) {
      const int plus = centre[u + v * step];
      const int minus = centre[u - v * step];
      v_sum += plus - minus;
      m10 += u * (plus + minus);
    }
    m01 += v * v_sum;
  }
  return FastAtan2Degrees(static_cast<float>(m01), static_cast<float>(m10));
}

void Describe(const cv::Mat& blurred, const cv::KeyPoint& kp, float level_scale,
              const std::vector<OrbTestPair>& pairs, uchar* out) {
  const float angle = kp.angle * static_cast<float>(CV_PI / 180.f);
  const float a = std::cos(angle);
  const float b = std::sin(angle);
  const float inv = 1.f / level_scale;
  const uchar* centre = blurred.ptr<uchar>(cvRound(kp.pt.y * inv)) + cvRound(kp.pt.x * inv);
  const int step = static_cast<int>(blurred.step);
  const auto value = [&](const cv::Point& p) {
    const float x = p.x * a - p.y * b;
    const float y = p.x * b + p.y * a;
    return centre[cvRound(y) * step + cvRound(x)];
  };
  for (int i = 0; i < kDescriptorBytes; ++i) {
    int bits = 0;
    for (int j = 0; j < 8; ++j) {
      const OrbTestPair& t = pairs[8 * i + j];
      bits |= static_cast<int>(value(t.first) < value(t.second)) << j;
    }
    out[i] = static_cast<uchar>(bits);
  }
}

}  // namespace

const std::vector<OrbTestPair>& OrbTestPairs() {
  static const std::vector<OrbTestPair> pairs = ReadTestPairs();
  return pairs;
}

OrbDetector::OrbDetector(int max_features, int fast_threshold, float scale_factor, int levels)
    : max_features_(max_features),
      fast_threshold_(fast_threshold),
      scale_factor_(scale_factor),
      levels_(levels) {
  MAPLESS_CHECK(max_features >= 1,
                "OrbDetector: max_features = " << max_features << "; must be >= 1");
  MAPLESS_CHECK(levels >= 1, "OrbDetector: levels = " << levels << "; must be >= 1");
  MAPLESS_CHECK(scale_factor > 1.f,
                "OrbDetector: scale_factor = " << scale_factor << "; must be > 1");
}

void OrbDetector::DetectAndCompute(const cv::Mat& grey, std::vector<cv::KeyPoint>* keypoints,
                                   cv::Mat* descriptors) const {
  keypoints->clear();
  const std::vector<OrbTestPair>& pairs = OrbTestPairs();
  if (pairs.empty() || grey.type() != CV_8UC1) {
    // Test pairs not readable off this OpenCV, or not a grey image (cv::ORB converts colour):
    // OpenCV's own ORB, at its own cost.
    cv::ORB::create(max_features_, static_cast<float>(scale_factor_), levels_, kEdge, 0, 2,
                    cv::ORB::HARRIS_SCORE, kPatch, fast_threshold_)
        ->detectAndCompute(grey, cv::noArray(), *keypoints, *descriptors);
    return;
  }
  if (grey.empty()) {
    descriptors->release();
    return;
  }

  // The pyramid: each level resized from the one before, as cv::ORB does, without its borders.
  std::vector<float> scale(levels_);
  std::vector<cv::Mat> level(levels_);
  for (int l = 0; l < levels_; ++l) {
    scale[l] = static_cast<float>(std::pow(scale_factor_, static_cast<double>(l)));
    const cv::Size size(cvRound(grey.cols / scale[l]), cvRound(grey.rows / scale[l]));
    if (l == 0) {
      level[l] = grey;
    } else {
      cv::resize(level[l - 1], level[l], size, 0, 0, cv::INTER_LINEAR_EXACT);
    }
  }

  // Features per level: a geometric series in the scale, the rest to the last level.
  std::vector<int> per_level(levels_);
  {
    const float factor = static_cast<float>(1.0 / scale_factor_);
    float desired = max_features_ * (1 - factor) /
                    (1 - static_cast<float>(
                             std::pow(static_cast<double>(factor), static_cast<double>(levels_))));
    int sum = 0;
    for (int l = 0; l < levels_ - 1; ++l) {
      per_level[l] = cvRound(desired);
      sum += per_level[l];
      desired *= factor;
    }
    per_level[levels_ - 1] = std::max(max_features_ - sum, 0);
  }

  // FAST corners away from each level's edge, the best 2x per level by FAST score.
  std::vector<cv::KeyPoint> candidates;
  std::vector<int> counts(levels_, 0);
  for (int l = 0; l < levels_; ++l) {
    const cv::Mat& img = level[l];
    if (img.cols <= 2 * kEdge || img.rows <= 2 * kEdge) continue;
    std::vector<cv::KeyPoint> kps;
    const cv::Rect inner(kFastMargin, kFastMargin, img.cols - 2 * kFastMargin,
                         img.rows - 2 * kFastMargin);
    cv::FAST(img(inner), kps, fast_threshold_, true);
    for (cv::KeyPoint& k : kps) k.pt += cv::Point2f(kFastMargin, kFastMargin);
    cv::KeyPointsFilter::runByImageBorder(kps, img.size(), kEdge);
    cv::KeyPointsFilter::retainBest(kps, 2 * per_level[l]);
    for (cv::KeyPoint& k : kps) {
      k.octave = l;
      k.size = kPatch * scale[l];
    }
    counts[l] = static_cast<int>(kps.size());
    candidates.insert(candidates.end(), kps.begin(), kps.end());
  }
  if (candidates.empty()) {  // (a level with candidates keeps at least one below)
    descriptors->release();
    return;
  }

  // Harris scores; the best per level; orientation; coordinates in the image.
  for (cv::KeyPoint& k : candidates) k.response = HarrisResponse(level[k.octave], k);
  {
    std::size_t offset = 0;
    for (int l = 0; l < levels_; ++l) {
      std::vector<cv::KeyPoint> kps(
          candidates.begin() + static_cast<std::ptrdiff_t>(offset),
          candidates.begin() + static_cast<std::ptrdiff_t>(offset + counts[l]));
      offset += static_cast<std::size_t>(counts[l]);
      cv::KeyPointsFilter::retainBest(kps, per_level[l]);
      keypoints->insert(keypoints->end(), kps.begin(), kps.end());
    }
  }
  const std::vector<int> umax = CircleHalfWidths();
  for (cv::KeyPoint& k : *keypoints) {
    k.angle = CentroidAngle(level[k.octave], k, umax);
    k.pt *= scale[k.octave];
  }

  // Descriptors on the blurred levels (only the part the tests read is blurred).
  std::vector<cv::Mat> blurred(levels_);
  for (const cv::KeyPoint& k : *keypoints) {
    cv::Mat& out = blurred[k.octave];
    if (!out.empty()) continue;
    const cv::Mat& img = level[k.octave];
    out.create(img.size(), CV_8U);
    const cv::Rect part(kBlurMargin, kBlurMargin, img.cols - 2 * kBlurMargin,
                        img.rows - 2 * kBlurMargin);
    cv::Mat dst = out(part);
    cv::GaussianBlur(img(part), dst, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
  }
  descriptors->create(static_cast<int>(keypoints->size()), kDescriptorBytes, CV_8U);
  for (std::size_t i = 0; i < keypoints->size(); ++i) {
    const cv::KeyPoint& k = (*keypoints)[i];
    Describe(blurred[k.octave], k, scale[k.octave], pairs,
             descriptors->ptr<uchar>(static_cast<int>(i)));
  }
}

}  // namespace mapless::features

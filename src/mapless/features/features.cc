#include "mapless/features/features.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::features {
namespace {

struct TypeName {
  DetectorType type;
  const char* name;
};
constexpr TypeName kTypeNames[] = {{DetectorType::kOrb, "orb"},
                                   {DetectorType::kAkaze, "akaze"},
                                   {DetectorType::kAkazeUpright, "akaze_upright"},
                                   {DetectorType::kSift, "sift"},
                                   {DetectorType::kAkazeSift, "akaze_sift"}};

}  // namespace

DescriptorLayout DescriptorLayoutOf(DetectorType type) {
  switch (type) {
    case DetectorType::kOrb:
      return {CV_8U, 32};
    case DetectorType::kAkaze:
    case DetectorType::kAkazeUpright:
      return {CV_8U, 61};  // MLDB, full size: 486 bits
    case DetectorType::kSift:
    case DetectorType::kAkazeSift:
      return {CV_32F, 128};
  }
  return {};
}

bool IsBinary(DetectorType type) { return DescriptorLayoutOf(type).type == CV_8U; }

DetectorType ParseDetectorType(const std::string& name) {
  for (const auto& t : kTypeNames) {
    if (name == t.name) return t.type;
  }
  throw InputError("unknown detector '" + name +
                   "' (known: orb, akaze, akaze_upright, sift, akaze_sift)");
}

const char* DetectorTypeName(DetectorType type) {
  for (const auto& t : kTypeNames) {
    if (type == t.type) return t.name;
  }
  return "?";
}

void FeatureOptions::Validate() const {
  MAPLESS_CHECK(max_features >= 10 && max_features <= 100000,
                "FeatureOptions.max_features = " << max_features << "; must be in [10, 100000]");
  MAPLESS_CHECK(
      orb_fast_threshold >= 1 && orb_fast_threshold <= 255,
      "FeatureOptions.orb_fast_threshold = " << orb_fast_threshold << "; must be in [1, 255]");
  MAPLESS_CHECK(akaze_threshold > 0.0,
                "FeatureOptions.akaze_threshold = " << akaze_threshold << "; must be > 0");
}

void MatchOptions::Validate() const {
  MAPLESS_CHECK(ratio > 0.0 && ratio <= 1.0,
                "MatchOptions.ratio = " << ratio << "; must be in (0, 1]");
  MAPLESS_CHECK(max_dy_px > 0.0, "MatchOptions.max_dy_px = " << max_dy_px << "; must be > 0");
  MAPLESS_CHECK(max_ddx_px > 0.0, "MatchOptions.max_ddx_px = " << max_ddx_px << "; must be > 0");
  MAPLESS_CHECK(std::isfinite(expected_dx_px),
                "MatchOptions.expected_dx_px = " << expected_dx_px << "; must be finite");
}

FeatureExtractor::FeatureExtractor(FeatureOptions options) : options_(options) {
  options_.Validate();
  switch (options_.type) {
    case DetectorType::kOrb:
      orb_ = std::make_unique<OrbDetector>(options_.max_features, options_.orb_fast_threshold);
      break;
    case DetectorType::kAkaze:
      detector_ = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3,
                                    static_cast<float>(options_.akaze_threshold));
      break;
    case DetectorType::kAkazeUpright:
      detector_ = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB_UPRIGHT, 0, 3,
                                    static_cast<float>(options_.akaze_threshold));
      break;
    case DetectorType::kSift:
      detector_ = cv::SIFT::create(options_.max_features);
      break;
    case DetectorType::kAkazeSift:
      detector_ = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB_UPRIGHT, 0, 3,
                                    static_cast<float>(options_.akaze_threshold));
      describer_ = cv::SIFT::create();
      break;
  }
}

Features FeatureExtractor::Extract(const cv::Mat& image) const {
  MAPLESS_CHECK(!image.empty(), "FeatureExtractor: empty image");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  Features out;
  out.binary = IsBinary(options_.type);
  if (orb_) {
    orb_->DetectAndCompute(grey, &out.keypoints, &out.descriptors);
  } else if (describer_) {
    detector_->detect(grey, out.keypoints);
    // The strongest max_features; upright (a ground robot's camera does not roll).
    cv::KeyPointsFilter::retainBest(out.keypoints, options_.max_features);
    for (auto& k : out.keypoints) k.angle = 0.0F;
    describer_->compute(grey, out.keypoints, out.descriptors);
  } else {
    detector_->detectAndCompute(grey, cv::noArray(), out.keypoints, out.descriptors);
  }
  return out;
}

namespace {

constexpr int kNoMatch = std::numeric_limits<int>::max();

// Hamming distance of two binary descriptors of `bytes` bytes (8 at a time, then the tail).
inline int Hamming(const uchar* a, const uchar* b, int bytes) {
  int d = 0;
  int i = 0;
  for (; i + 8 <= bytes; i += 8) {
    std::uint64_t x = 0;
    std::uint64_t y = 0;
    std::memcpy(&x, a + i, 8);
    std::memcpy(&y, b + i, 8);
    d += __builtin_popcountll(x ^ y);
  }
  for (; i < bytes; ++i) d += __builtin_popcount(static_cast<unsigned>(a[i] ^ b[i]));
  return d;
}

// The best and second best distances of one query feature, and the best's index. Candidates may
// come in any order: ties go to the lower index, as in OpenCV's BFMatcher (batchDistance).
struct Best2 {
  int best = -1;
  int best_d = kNoMatch;
  int second_d = kNoMatch;
  void Visit(int j, int d) {
    if (d < best_d || (d == best_d && j < best)) {
      second_d = best_d;
      best_d = d;
      best = j;
    } else if (d < second_d) {
      second_d = d;
    }
  }
};

// Train features in cells of kCell x kCell pixels, so a query feature looks only at the cells its
// guided-matching window overlaps.
constexpr float kCell = 16.0f;

struct Grid {
  int cols = 0;
  int rows = 0;
  float x0 = 0.0f;
  float y0 = 0.0f;
  std::vector<int> start;  // cell c holds index[start[c] .. start[c + 1])
  std::vector<int> index;
  explicit Grid(const std::vector<cv::KeyPoint>& kp) {
    float x1 = 0.0f;
    float y1 = 0.0f;
    x0 = y0 = std::numeric_limits<float>::max();
    for (const auto& k : kp) {
      x0 = std::min(x0, k.pt.x);
      y0 = std::min(y0, k.pt.y);
      x1 = std::max(x1, k.pt.x);
      y1 = std::max(y1, k.pt.y);
    }
    if (kp.empty()) x0 = y0 = 0.0f;
    // Keypoints come from images, so their coordinates are bounded; the grid is capped at 4096
    // cells a side all the same, and a NaN coordinate falls into cell 0.
    cols = Bin((x1 - x0) / kCell, 4096) + 1;
    rows = Bin((y1 - y0) / kCell, 4096) + 1;
    std::vector<int> cell_of(kp.size());
    start.assign(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows) + 1, 0);
    for (std::size_t j = 0; j < kp.size(); ++j) {
      cell_of[j] = Cell(Col(kp[j].pt.x), Row(kp[j].pt.y));
      ++start[static_cast<std::size_t>(cell_of[j]) + 1];
    }
    for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    index.resize(kp.size());
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (std::size_t j = 0; j < kp.size(); ++j)
      index[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell_of[j])]++)] =
          static_cast<int>(j);
  }
  int Col(double x) const { return Bin((x - x0) / kCell, cols); }
  int Row(double y) const { return Bin((y - y0) / kCell, rows); }
  // floor(v) clamped to [0, n - 1]; NaN gives 0.
  static int Bin(double v, int n) {
    if (!(v >= 1.0)) return 0;
    return v >= n - 1.0 ? n - 1 : static_cast<int>(v);
  }
  int Cell(int col, int row) const { return row * cols + col; }
};

// Binary descriptors: each allowed distance is computed once and serves both directions (the
// forward two best and the mutual check). Guided matching visits only the train features in the
// grid cells that the window overlaps, then applies the window's exact test. The matches are
// exactly BFMatcher's (knnMatch with the window as its mask; tested against it).
// On x86-64, GCC builds it twice, with and without the popcnt instruction, and picks at load time.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("popcnt", "default")))
#endif
std::vector<cv::DMatch>
MatchBinary(const Features& query, const Features& train, const MatchOptions& options) {
  const int nq = query.descriptors.rows;
  const int nt = train.descriptors.rows;
  const int bytes = query.descriptors.cols;
  const bool guided = options.max_ddx_px < 1e8;
  std::vector<Best2> forward(static_cast<std::size_t>(nq));
  // Backward (mutual): the best query per train feature. Query features are visited in
  // increasing index, so a strict < keeps the lowest index on ties.
  std::vector<int> back(static_cast<std::size_t>(nt), -1);
  std::vector<int> back_d(static_cast<std::size_t>(nt), kNoMatch);
  const auto visit = [&](int i, int j) {
    const int d = Hamming(query.descriptors.ptr<uchar>(i), train.descriptors.ptr<uchar>(j), bytes);
    forward[static_cast<std::size_t>(i)].Visit(j, d);
    const auto tj = static_cast<std::size_t>(j);
    if (d < back_d[tj]) {
      back_d[tj] = d;
      back[tj] = i;
    }
  };
  if (!guided) {
    for (int i = 0; i < nq; ++i)
      for (int j = 0; j < nt; ++j) visit(i, j);
  } else {
    const Grid grid(train.keypoints);
    for (int i = 0; i < nq; ++i) {
      const cv::Point2f& a = query.keypoints[static_cast<std::size_t>(i)].pt;
      // Train x in a.x - expected +- max_ddx, y in a.y +- max_dy (one cell more each side:
      // the exact test below decides).
      const double cx = a.x - options.expected_dx_px;
      const double dy = std::min(options.max_dy_px, 1e7);
      const int c0 = grid.Col(cx - options.max_ddx_px - 1.0);
      const int c1 = grid.Col(cx + options.max_ddx_px + 1.0);
      const int r0 = grid.Row(a.y - dy - 1.0);
      const int r1 = grid.Row(a.y + dy + 1.0);
      for (int r = r0; r <= r1; ++r) {
        for (int c = c0; c <= c1; ++c) {
          const auto cell = static_cast<std::size_t>(grid.Cell(c, r));
          for (int k = grid.start[cell]; k < grid.start[cell + 1]; ++k) {
            const int j = grid.index[static_cast<std::size_t>(k)];
            const cv::Point2f& b = train.keypoints[static_cast<std::size_t>(j)].pt;
            if (std::abs(a.x - b.x - options.expected_dx_px) <= options.max_ddx_px &&
                std::abs(a.y - b.y) <= options.max_dy_px) {
              visit(i, j);
            }
          }
        }
      }
    }
  }
  std::vector<cv::DMatch> out;
  for (int i = 0; i < nq; ++i) {
    const Best2& f = forward[static_cast<std::size_t>(i)];
    if (f.best < 0) continue;
    // Lowe's ratio test when there is a second candidate (with BFMatcher's knnMatch, a lone
    // candidate in the window passes too).
    if (options.ratio < 1.0 && f.second_d != kNoMatch &&
        !(f.best_d < options.ratio * static_cast<double>(f.second_d)))
      continue;
    const cv::Point2f& a = query.keypoints[static_cast<std::size_t>(i)].pt;
    const cv::Point2f& b = train.keypoints[static_cast<std::size_t>(f.best)].pt;
    if (std::abs(b.y - a.y) > options.max_dy_px) continue;
    if (options.mutual && back[static_cast<std::size_t>(f.best)] != i) continue;
    out.emplace_back(i, f.best, static_cast<float>(f.best_d));
  }
  return out;
}

}  // namespace

namespace {

// The nearest train descriptor of each query descriptor by L2, ties to the lower index (as
// BFMatcher); with `mutual`, only pairs that are each other's nearest. The distances come from
// cv::batchDistance, the kernel BFMatcher uses, once for both directions.
std::vector<cv::DMatch> MatchFloatNearest(const Features& query, const Features& train,
                                          bool mutual) {
  cv::Mat distances;  // query x train, squared L2
  cv::batchDistance(query.descriptors, train.descriptors, distances, CV_32F, cv::noArray(),
                    cv::NORM_L2SQR);
  const int n = distances.rows;
  const int m = distances.cols;
  std::vector<int> best_query(static_cast<std::size_t>(m), -1);
  std::vector<float> best_query_d(static_cast<std::size_t>(m), std::numeric_limits<float>::max());
  std::vector<int> best_train(static_cast<std::size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    const float* row = distances.ptr<float>(i);
    float best = std::numeric_limits<float>::max();
    for (int j = 0; j < m; ++j) {
      const float d = row[j];
      if (d < best) {
        best = d;
        best_train[static_cast<std::size_t>(i)] = j;
      }
      if (d < best_query_d[static_cast<std::size_t>(j)]) {
        best_query_d[static_cast<std::size_t>(j)] = d;
        best_query[static_cast<std::size_t>(j)] = i;
      }
    }
  }
  std::vector<cv::DMatch> out;
  for (int i = 0; i < n; ++i) {
    const int j = best_train[static_cast<std::size_t>(i)];
    if (j < 0 || (mutual && best_query[static_cast<std::size_t>(j)] != i)) continue;
    out.emplace_back(i, j, std::sqrt(distances.at<float>(i, j)));
  }
  return out;
}

}  // namespace

std::vector<cv::DMatch> MatchFeatures(const Features& query, const Features& train,
                                      const MatchOptions& options) {
  std::vector<cv::DMatch> out;
  if (query.descriptors.empty() || train.descriptors.empty()) return out;
  MAPLESS_CHECK(query.binary == train.binary && query.descriptors.cols == train.descriptors.cols,
                "MatchFeatures: descriptors of different kinds");
  if (query.binary) return MatchBinary(query, train, options);
  // Float descriptors (SIFT): without a ratio test or a window, every distance once and the best
  // of each row and column from it (BFMatcher computes them twice with the mutual check).
  if (options.ratio >= 1.0 && options.max_ddx_px >= 1e8 && options.max_dy_px >= 1e8)
    return MatchFloatNearest(query, train, options.mutual);
  return MatchFeaturesBruteForce(query, train, options);
}

std::vector<cv::DMatch> MatchFeaturesBruteForce(const Features& query, const Features& train,
                                                const MatchOptions& options) {
  std::vector<cv::DMatch> out;
  if (query.descriptors.empty() || train.descriptors.empty()) return out;
  MAPLESS_CHECK(query.binary == train.binary && query.descriptors.cols == train.descriptors.cols,
                "MatchFeaturesBruteForce: descriptors of different kinds");
  cv::BFMatcher matcher(query.binary ? cv::NORM_HAMMING : cv::NORM_L2);
  const bool guided = options.max_ddx_px < 1e8;
  cv::Mat mask;  // query x train, 1 where a match is allowed (guided matching only)
  if (guided) {
    mask = cv::Mat::zeros(static_cast<int>(query.keypoints.size()),
                          static_cast<int>(train.keypoints.size()), CV_8U);
    for (int i = 0; i < mask.rows; ++i) {
      const cv::Point2f& a = query.keypoints[static_cast<std::size_t>(i)].pt;
      auto* row = mask.ptr<uchar>(i);
      for (int j = 0; j < mask.cols; ++j) {
        const cv::Point2f& b = train.keypoints[static_cast<std::size_t>(j)].pt;
        row[j] = std::abs(a.x - b.x - options.expected_dx_px) <= options.max_ddx_px &&
                 std::abs(a.y - b.y) <= options.max_dy_px;
      }
    }
  }
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(query.descriptors, train.descriptors, knn, 2, mask);
  std::vector<int> best_query_for_train;
  if (options.mutual) {
    std::vector<cv::DMatch> back;
    matcher.match(train.descriptors, query.descriptors, back,
                  guided ? cv::Mat(mask.t()) : cv::Mat());
    best_query_for_train.assign(train.keypoints.size(), -1);
    for (const auto& m : back)
      best_query_for_train[static_cast<std::size_t>(m.queryIdx)] = m.trainIdx;
  }
  for (const auto& k : knn) {
    if (k.empty()) continue;
    if (options.ratio < 1.0 && k.size() >= 2 && !(k[0].distance < options.ratio * k[1].distance))
      continue;
    const cv::Point2f& a = query.keypoints[static_cast<std::size_t>(k[0].queryIdx)].pt;
    const cv::Point2f& b = train.keypoints[static_cast<std::size_t>(k[0].trainIdx)].pt;
    if (std::abs(b.y - a.y) > options.max_dy_px) continue;
    if (options.mutual &&
        best_query_for_train[static_cast<std::size_t>(k[0].trainIdx)] != k[0].queryIdx) {
      continue;
    }
    out.push_back(k[0]);
  }
  return out;
}

}  // namespace mapless::features

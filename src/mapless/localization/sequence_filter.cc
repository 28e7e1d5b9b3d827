#include "mapless/localization/sequence_filter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::localization {

void SequenceFilterOptions::Validate() const {
  MAPLESS_CHECK(width >= 4 && width <= 1024 && height >= 4 && height <= 1024,
                "SequenceFilterOptions: image " << width << "x" << height
                                                << "; each side must be in [4, 1024]");
  MAPLESS_CHECK(patch_px >= 2, "SequenceFilterOptions.patch_px = " << patch_px << "; must be >= 2");
  MAPLESS_CHECK(contrast_window >= 1,
                "SequenceFilterOptions.contrast_window = " << contrast_window << "; must be >= 1");
  MAPLESS_CHECK(temperature > 0.0 && std::isfinite(temperature),
                "SequenceFilterOptions.temperature = " << temperature << "; must be > 0");
  MAPLESS_CHECK(std::isfinite(advance) && advance >= 0.0,
                "SequenceFilterOptions.advance = " << advance << "; must be >= 0");
  MAPLESS_CHECK(advance_sigma > 0.0 && std::isfinite(advance_sigma),
                "SequenceFilterOptions.advance_sigma = " << advance_sigma << "; must be > 0");
  MAPLESS_CHECK(
      uniform_mixing >= 0.0 && uniform_mixing < 1.0,
      "SequenceFilterOptions.uniform_mixing = " << uniform_mixing << "; must be in [0, 1)");
  MAPLESS_CHECK(start_sigma >= 0.0 && std::isfinite(start_sigma),
                "SequenceFilterOptions.start_sigma = " << start_sigma << "; must be >= 0");
  MAPLESS_CHECK(confidence_window >= 0, "SequenceFilterOptions.confidence_window = "
                                            << confidence_window << "; must be >= 0");
}

cv::Mat SequenceDescriptor(const cv::Mat& image, const SequenceFilterOptions& options) {
  MAPLESS_CHECK(!image.empty(), "sequence descriptor: empty image");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  cv::Mat small;
  cv::resize(grey, small, cv::Size(options.width, options.height), 0, 0, cv::INTER_AREA);
  cv::Mat out;
  small.convertTo(out, CV_32F);
  for (int y = 0; y < out.rows; y += options.patch_px) {
    for (int x = 0; x < out.cols; x += options.patch_px) {
      cv::Mat patch = out(cv::Rect(x, y, std::min(options.patch_px, out.cols - x),
                                   std::min(options.patch_px, out.rows - y)));
      cv::Scalar mean, stddev;
      cv::meanStdDev(patch, mean, stddev);
      const double scale = stddev[0] > 1e-6 ? 1.0 / stddev[0] : 0.0;  // a flat patch: zeros
      patch.convertTo(patch, CV_32F, scale, -mean[0] * scale);
    }
  }
  return out.reshape(1, 1).clone();
}

std::vector<double> EnhancedDifferences(const cv::Mat& route, const cv::Mat& query, int window) {
  MAPLESS_CHECK(route.cols == query.cols && query.rows == 1 && route.type() == CV_32F &&
                    query.type() == CV_32F,
                "EnhancedDifferences: descriptors of different kinds");
  const int n = route.rows;
  std::vector<double> d(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    d[static_cast<std::size_t>(i)] = cv::norm(route.row(i), query, cv::NORM_L1) / query.cols;
  // Prefix sums for the window means and variances.
  std::vector<double> s1(static_cast<std::size_t>(n) + 1, 0.0), s2(s1);
  for (int i = 0; i < n; ++i) {
    const double v = d[static_cast<std::size_t>(i)];
    s1[static_cast<std::size_t>(i) + 1] = s1[static_cast<std::size_t>(i)] + v;
    s2[static_cast<std::size_t>(i) + 1] = s2[static_cast<std::size_t>(i)] + v * v;
  }
  std::vector<double> z(d.size());
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - window);
    const int b = std::min(n - 1, i + window);
    const double count = b - a + 1;
    const double mean =
        (s1[static_cast<std::size_t>(b) + 1] - s1[static_cast<std::size_t>(a)]) / count;
    const double var =
        (s2[static_cast<std::size_t>(b) + 1] - s2[static_cast<std::size_t>(a)]) / count -
        mean * mean;
    z[static_cast<std::size_t>(i)] =
        (d[static_cast<std::size_t>(i)] - mean) / std::sqrt(std::max(var, 1e-12));
  }
  return z;
}

SequenceFilter::SequenceFilter(cv::Mat route, SequenceFilterOptions options)
    : route_(std::move(route)), options_(options) {
  options_.Validate();
  MAPLESS_CHECK(route_.rows >= 2,
                "sequence filter: the route needs at least 2 images, got " << route_.rows);
  belief_.assign(static_cast<std::size_t>(route_.rows), 1.0 / route_.rows);
  if (options_.start_sigma > 0.0) {  // near the first image, and a floor anywhere
    double sum = 0.0;
    for (int i = 0; i < route_.rows; ++i) {
      const double x = i / options_.start_sigma;
      auto& b = belief_[static_cast<std::size_t>(i)];
      b = std::exp(-0.5 * x * x) + options_.uniform_mixing;
      sum += b;
    }
    for (double& b : belief_) b /= sum;
  }
  const int half = static_cast<int>(std::ceil(4.0 * options_.advance_sigma)) + 1;
  for (int k = -half; k <= half; ++k) {
    kernel_.push_back(std::exp(-0.5 * k * k / (options_.advance_sigma * options_.advance_sigma)));
  }
}

SequenceEstimate SequenceFilter::Update(const cv::Mat& query_descriptor) {
  const int n = route_.rows;
  const auto size = static_cast<std::size_t>(n);
  if (!first_) {  // predict: advance, spread, and a little of anywhere
    std::vector<double> predicted(size, 0.0);
    const int half = static_cast<int>(kernel_.size() / 2);
    const double shift = options_.advance;
    const int whole = static_cast<int>(std::floor(shift));
    const double frac = shift - whole;  // split between the two nearest whole advances
    for (int i = 0; i < n; ++i) {
      const double b = belief_[static_cast<std::size_t>(i)];
      if (b == 0.0) continue;
      for (int k = -half; k <= half; ++k) {
        const double w = b * kernel_[static_cast<std::size_t>(k + half)];
        const int j0 = i + whole + k;
        if (j0 >= 0 && j0 < n) predicted[static_cast<std::size_t>(j0)] += w * (1.0 - frac);
        if (frac > 0.0 && j0 + 1 >= 0 && j0 + 1 < n)
          predicted[static_cast<std::size_t>(j0) + 1] += w * frac;
      }
    }
    double sum = 0.0;
    for (double p : predicted) sum += p;
    for (std::size_t i = 0; i < size; ++i) {
      belief_[i] = (1.0 - options_.uniform_mixing) * (sum > 0.0 ? predicted[i] / sum : 1.0 / n) +
                   options_.uniform_mixing / n;
    }
  }
  first_ = false;
  const std::vector<double> z =
      EnhancedDifferences(route_, query_descriptor, options_.contrast_window);
  const double z_min = *std::min_element(z.begin(), z.end());
  double sum = 0.0;
  for (std::size_t i = 0; i < size; ++i) {
    belief_[i] *= std::exp(-(z[i] - z_min) / options_.temperature);
    sum += belief_[i];
  }
  for (double& b : belief_) b /= sum;
  SequenceEstimate out;
  out.index = static_cast<int>(std::max_element(belief_.begin(), belief_.end()) - belief_.begin());
  for (int k = std::max(0, out.index - options_.confidence_window);
       k <= std::min(n - 1, out.index + options_.confidence_window); ++k) {
    out.confidence += belief_[static_cast<std::size_t>(k)];
  }
  return out;
}

std::vector<SequenceEstimate> FilterSequence(const std::vector<cv::Mat>& database,
                                             const std::vector<cv::Mat>& queries,
                                             const SequenceFilterOptions& options) {
  options.Validate();
  cv::Mat route;
  for (const cv::Mat& image : database) route.push_back(SequenceDescriptor(image, options));
  SequenceFilter filter(route, options);
  std::vector<SequenceEstimate> out;
  out.reserve(queries.size());
  for (const cv::Mat& image : queries)
    out.push_back(filter.Update(SequenceDescriptor(image, options)));
  return out;
}

std::vector<int> SeqSlamPastOnly(const std::vector<std::vector<double>>& differences,
                                 int sequence_length) {
  MAPLESS_CHECK(sequence_length >= 1, "SeqSLAM: sequence length " << sequence_length);
  std::vector<int> out;
  for (std::size_t q = 0; q < differences.size(); ++q) {
    const int n = static_cast<int>(differences[q].size());
    const int length = std::min<int>(sequence_length, static_cast<int>(q) + 1);
    double best = std::numeric_limits<double>::infinity();
    int best_index = 0;
    for (int i = 0; i < n; ++i) {
      for (int v10 = 8; v10 <= 12; ++v10) {  // 0.8 to 1.2 route images per query
        double sum = 0.0;
        bool inside = true;
        for (int k = 0; k < length && inside; ++k) {
          const int j = i - static_cast<int>(std::lround(v10 * k / 10.0));
          inside = j >= 0;
          if (inside)
            sum += differences[q - static_cast<std::size_t>(k)][static_cast<std::size_t>(j)];
        }
        if (inside && sum / length < best) {
          best = sum / length;
          best_index = i;
        }
      }
    }
    out.push_back(best_index);
  }
  return out;
}

}  // namespace mapless::localization

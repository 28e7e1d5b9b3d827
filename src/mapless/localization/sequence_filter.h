// Localization of a traversal against a route of images across seasons (issue 66): a Bayes filter
// (an HMM's forward pass) over the route images whose observation is dense, not the k kernels of
// Markov localization (markov.h). Every route image gets a likelihood from its difference to the
// query, after the two normalisations that make images of different seasons comparable
// (Milford & Wyeth's SeqSLAM, ICRA 2012): each image patch-normalised (every PxP patch to zero mean
// and unit variance, so that a snowy field and a green one differ only where their structure does),
// and each difference contrast-enhanced against the differences of its route neighbours (z-score
// over +-R images, so that a place is judged against the places around it). The motion model is an
// advance per query with a Gaussian spread and a little uniform mixing (the robot may stop or speed
// up); only past queries are used. The belief starts uniform, or near the route's first image
// when told (`start_sigma`). The confidence is the belief mass around its maximum.
//
// Also here, for evaluations, the SeqSLAM-style baseline: the same differences, and for each query
// the route image that ends the straight sequence (0.8 to 1.2 route images per query) of least
// summed difference over the last `sequence_length` queries.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mapless::localization {

struct SequenceFilterOptions {
  int width = 64;  // low-resolution image, px
  int height = 32;
  int patch_px = 8;            // patch normalisation
  int contrast_window = 10;    // R, route images each side
  double temperature = 3.0;    // likelihood exp(-(z - z_min) / temperature)
  double advance = 1.0;        // route images per query ...
  double advance_sigma = 0.5;  // ... and its spread per query (a place's worth of speed change
                               // in a few queries; 1 blurs the belief over neighbouring places)
  double uniform_mixing = 1e-3;
  // Where the traversal starts: anywhere (0: a uniform belief, the default: no assumption), or
  // within about start_sigma route images of the route's first image (a repeat that starts where
  // the teach did).
  double start_sigma = 0.0;
  // Confidence = belief mass within +- this many images of the estimate: the probability, by the
  // filter's own belief, that the estimate is within that many places (the evaluation's 5).
  int confidence_window = 5;
  void Validate() const;
};

// The low-resolution, patch-normalised image as one row of floats.
cv::Mat SequenceDescriptor(const cv::Mat& image, const SequenceFilterOptions& options);

// Mean absolute difference of `query` (one row) to each row of `route`, contrast-enhanced over
// +-window route images: one z-score per route image, lower is more alike.
std::vector<double> EnhancedDifferences(const cv::Mat& route, const cv::Mat& query, int window);

struct SequenceEstimate {
  int index = -1;
  double confidence = 0.0;
};

class SequenceFilter {
 public:
  SequenceFilter(cv::Mat route, SequenceFilterOptions options);  // route: one descriptor per row
  SequenceEstimate Update(const cv::Mat& query_descriptor);
  const std::vector<double>& belief() const { return belief_; }

 private:
  cv::Mat route_;
  SequenceFilterOptions options_;
  std::vector<double> belief_;
  std::vector<double> kernel_;
  bool first_ = true;
};

// Every query in order through a filter on the database images' route.
std::vector<SequenceEstimate> FilterSequence(const std::vector<cv::Mat>& database,
                                             const std::vector<cv::Mat>& queries,
                                             const SequenceFilterOptions& options);

// The SeqSLAM-style baseline over past queries only; `differences[q]` are query q's
// EnhancedDifferences. Returns the route image for each query.
std::vector<int> SeqSlamPastOnly(const std::vector<std::vector<double>>& differences,
                                 int sequence_length);

}  // namespace mapless::localization

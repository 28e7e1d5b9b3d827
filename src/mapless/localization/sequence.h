// Localization of a sequence of query images against a database of route images (the images in
// route order): the database is compressed into an eigenspace (incremental PCA by default, or
// batch), and each query is localized by its nearest projection or by Markov localization with a
// constant advance per query (the query traverses the same route in the same direction; without
// odometry the advance is the motion model's velocity). This is what `mapless localize` runs.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/appearance/image.h"
#include "mapless/appearance/pca.h"
#include "mapless/localization/markov.h"

namespace mapless::localization {

// kSequenceFilter: sequence_filter.h (no eigenspace; `mapless localize`'s default since issue 66).
enum class SequenceMethod { kNearest, kMarkov, kSequenceFilter };
// "nn", "markov" or "sequence"; throws InputError naming the value otherwise.
SequenceMethod ParseSequenceMethod(const std::string& name);

struct SequenceLocalizationOptions {
  SequenceMethod method = SequenceMethod::kMarkov;
  appearance::AppearanceImageOptions image;
  appearance::IncrementalPcaOptions pca;
  bool incremental_pca = true;  // false: batch PCA (SVD) with pca.max_dimensions components
  MarkovOptions markov;
  double advance_per_query = 1.0;  // Markov motion model: database images per query image ...
  double advance_sigma = 0.2;      // ... and its standard deviation per query, images
  void Validate() const;
};

struct QueryLocalization {
  int index = -1;            // database image (route order)
  double probability = 0.0;  // Markov: belief mass around the index; nn: 1 - d1/d2 (distinctness)
  LocalizationStatus status = LocalizationStatus::kUninitialized;
};

// The eigenspace of the database images (route order).
appearance::Eigenspace BuildRouteEigenspace(const std::vector<cv::Mat>& database,
                                            const SequenceLocalizationOptions& options);

std::vector<QueryLocalization> LocalizeSequence(const appearance::Eigenspace& route,
                                                const std::vector<cv::Mat>& queries,
                                                const SequenceLocalizationOptions& options);

}  // namespace mapless::localization

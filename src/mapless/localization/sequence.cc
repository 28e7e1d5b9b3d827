#include "mapless/localization/sequence.h"

#include <cmath>

#include "mapless/core/check.h"
#include "mapless/localization/nearest.h"

namespace mapless::localization {

SequenceMethod ParseSequenceMethod(const std::string& name) {
  if (name == "nn") return SequenceMethod::kNearest;
  if (name == "markov") return SequenceMethod::kMarkov;
  if (name == "sequence") return SequenceMethod::kSequenceFilter;
  throw InputError("localization method '" + name + "' is unknown; use sequence, markov or nn");
}

void SequenceLocalizationOptions::Validate() const {
  image.Validate();
  pca.Validate();
  markov.Validate();
  MAPLESS_CHECK(
      std::isfinite(advance_per_query) && advance_per_query >= 0.0,
      "SequenceLocalizationOptions.advance_per_query = " << advance_per_query << "; must be >= 0");
  MAPLESS_CHECK(advance_sigma > 0.0,
                "SequenceLocalizationOptions.advance_sigma = " << advance_sigma << "; must be > 0");
}

appearance::Eigenspace BuildRouteEigenspace(const std::vector<cv::Mat>& database,
                                            const SequenceLocalizationOptions& options) {
  options.Validate();
  MAPLESS_CHECK(database.size() >= 2,
                "localization: the database needs at least 2 images, got " << database.size());
  if (options.incremental_pca) {
    appearance::IncrementalPca pca(options.pca);
    for (const cv::Mat& image : database)
      pca.Add(appearance::AppearanceVector(image, options.image));
    return pca.Model();
  }
  appearance::Matrix data(static_cast<Eigen::Index>(options.image.width) * options.image.height,
                          static_cast<Eigen::Index>(database.size()));
  for (std::size_t i = 0; i < database.size(); ++i) {
    data.col(static_cast<Eigen::Index>(i)) =
        appearance::AppearanceVector(database[i], options.image);
  }
  return appearance::BatchPcaSvd(data, options.pca.max_dimensions);
}

std::vector<QueryLocalization> LocalizeSequence(const appearance::Eigenspace& route,
                                                const std::vector<cv::Mat>& queries,
                                                const SequenceLocalizationOptions& options) {
  options.Validate();
  MAPLESS_CHECK(options.method != SequenceMethod::kSequenceFilter,
                "LocalizeSequence: the sequence filter takes images, not an eigenspace "
                "(FilterSequence)");
  std::vector<QueryLocalization> out;
  out.reserve(queries.size());
  MarkovOptions markov_options = options.markov;
  markov_options.motion_sigma_images = options.advance_sigma;
  markov_options.motion_sigma_fraction = 0.0;
  MarkovLocalizer markov(markov_options);
  markov.ResetUniform(route.images());
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const appearance::Vector z =
        route.Project(appearance::AppearanceVector(queries[i], options.image));
    QueryLocalization q;
    if (options.method == SequenceMethod::kNearest) {
      const std::vector<Neighbour> nn = NearestProjections(route.projections, z, 2);
      q.index = nn.front().index;
      q.probability = nn.size() > 1 && nn[1].distance > 0.0F
                          ? 1.0 - static_cast<double>(nn[0].distance) / nn[1].distance
                          : 1.0;
      q.status = LocalizationStatus::kTracking;
    } else {
      const Localization loc =
          markov.Update(route.projections, z, i == 0 ? 0.0 : options.advance_per_query);
      q.index = loc.index;
      q.probability = loc.probability;
      q.status = loc.status;
    }
    out.push_back(q);
  }
  return out;
}

}  // namespace mapless::localization

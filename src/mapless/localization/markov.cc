#include "mapless/localization/markov.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"

namespace mapless::localization {

const char* LocalizationStatusName(LocalizationStatus status) {
  switch (status) {
    case LocalizationStatus::kUninitialized:
      return "uninitialized";
    case LocalizationStatus::kTracking:
      return "tracking";
    case LocalizationStatus::kLost:
      return "lost";
  }
  return "?";
}

void MarkovOptions::Validate() const {
  MAPLESS_CHECK(kernels >= 1, "MarkovOptions.kernels = " << kernels << "; must be >= 1");
  MAPLESS_CHECK(kernel_sigma_images > 0.0,
                "MarkovOptions.kernel_sigma_images = " << kernel_sigma_images << "; must be > 0");
  MAPLESS_CHECK(motion_sigma_images > 0.0,
                "MarkovOptions.motion_sigma_images = " << motion_sigma_images << "; must be > 0");
  MAPLESS_CHECK(motion_sigma_fraction >= 0.0, "MarkovOptions.motion_sigma_fraction = "
                                                  << motion_sigma_fraction << "; must be >= 0");
  MAPLESS_CHECK(observation_floor >= 0.0 && observation_floor < 1.0,
                "MarkovOptions.observation_floor = " << observation_floor << "; must be in [0, 1)");
  MAPLESS_CHECK(uniform_mixing >= 0.0 && uniform_mixing < 1.0,
                "MarkovOptions.uniform_mixing = " << uniform_mixing << "; must be in [0, 1)");
  MAPLESS_CHECK(probability_window >= 0,
                "MarkovOptions.probability_window = " << probability_window << "; must be >= 0");
  MAPLESS_CHECK(lost_probability >= 0.0 && lost_probability <= 1.0,
                "MarkovOptions.lost_probability = " << lost_probability << "; must be in [0, 1]");
  MAPLESS_CHECK(min_agreement >= 0.0 && min_agreement <= 1.0,
                "MarkovOptions.min_agreement = " << min_agreement << "; must be in [0, 1]");
  MAPLESS_CHECK(lost_after_updates >= 1,
                "MarkovOptions.lost_after_updates = " << lost_after_updates << "; must be >= 1");
}

MarkovLocalizer::MarkovLocalizer(MarkovOptions options) : options_(options) { options_.Validate(); }

void MarkovLocalizer::set_uniform_mixing(double mixing) {
  options_.uniform_mixing = mixing;
  options_.Validate();
}

void MarkovLocalizer::ResetUniform(int route_images) {
  MAPLESS_CHECK(route_images >= 0, "Markov localization: route of " << route_images << " images");
  belief_ = Eigen::VectorXd::Constant(route_images, route_images > 0 ? 1.0 / route_images : 0.0);
  low_updates_ = 0;
}

void MarkovLocalizer::ResetAt(int route_images, double index, double sigma_images) {
  MAPLESS_CHECK(route_images >= 1, "Markov localization: route of " << route_images << " images");
  MAPLESS_CHECK(sigma_images > 0.0, "Markov localization: sigma = " << sigma_images);
  belief_.resize(route_images);
  for (int i = 0; i < route_images; ++i) {
    const double z = (i - index) / sigma_images;
    belief_(i) = std::exp(-0.5 * z * z) + 1e-9;
  }
  belief_ /= belief_.sum();
  low_updates_ = 0;
}

void MarkovLocalizer::Grow(int route_images) {
  const Eigen::Index old = belief_.size();
  if (route_images <= old) return;
  const double fill = old > 0 ? belief_.minCoeff() : 1.0;
  belief_.conservativeResize(route_images);
  belief_.tail(route_images - old).setConstant(fill);
  belief_ /= belief_.sum();
}

void MarkovLocalizer::Predict(double advance_images) {
  const int n = static_cast<int>(belief_.size());
  const double sigma =
      options_.motion_sigma_images + options_.motion_sigma_fraction * std::abs(advance_images);
  const int lo = static_cast<int>(std::floor(advance_images - 4.0 * sigma));
  const int hi = static_cast<int>(std::ceil(advance_images + 4.0 * sigma));
  std::vector<double> weights(static_cast<std::size_t>(hi - lo + 1));
  double total = 0.0;
  for (int j = lo; j <= hi; ++j) {
    const double z = (j - advance_images) / sigma;
    weights[static_cast<std::size_t>(j - lo)] = std::exp(-0.5 * z * z);
    total += weights[static_cast<std::size_t>(j - lo)];
  }
  scratch_ = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    const double mass = belief_(i) / total;
    if (mass == 0.0) continue;
    for (int j = lo; j <= hi; ++j) {
      // Motion past either end of the route stays at that end.
      const int target = std::clamp(i + j, 0, n - 1);
      scratch_(target) += mass * weights[static_cast<std::size_t>(j - lo)];
    }
  }
  belief_.swap(scratch_);
  if (options_.uniform_mixing > 0.0) {
    belief_ = belief_ * (1.0 - options_.uniform_mixing) +
              Eigen::VectorXd::Constant(n, options_.uniform_mixing / n);
  }
}

void MarkovLocalizer::ApplyIndexLimits() {
  const int n = static_cast<int>(belief_.size());
  const int lo = std::clamp(min_index_, 0, n - 1);
  const int hi = max_index_ < 0 ? n - 1 : std::clamp(max_index_, lo, n - 1);
  if (lo > 0 || hi < n - 1) {
    const double kept = belief_.segment(lo, hi - lo + 1).sum();
    if (kept > 0.0) {
      belief_.head(lo).setZero();
      belief_.tail(n - 1 - hi).setZero();
      belief_ /= kept;
    }
  }
}

Localization MarkovLocalizer::Peak() const {
  Localization result;
  const int n = static_cast<int>(belief_.size());
  if (n == 0) return result;
  Eigen::Index best = 0;
  belief_.maxCoeff(&best);
  result.index = static_cast<int>(best);
  const int w = options_.probability_window;
  const int from = std::max(0, result.index - w);
  const int to = std::min(n - 1, result.index + w);
  result.probability = belief_.segment(from, to - from + 1).sum();
  result.status = LocalizationStatus::kTracking;
  return result;
}

Localization MarkovLocalizer::Predict(int route_images, double advance_images) {
  MAPLESS_CHECK(std::isfinite(advance_images),
                "Markov localization: advance = " << advance_images << "; must be finite");
  if (route_images == 0) return {};
  if (belief_.size() == 0) ResetUniform(route_images);
  MAPLESS_CHECK(route_images >= belief_.size(), "Markov localization: the route shrank from "
                                                    << belief_.size() << " to " << route_images
                                                    << " images");
  Grow(route_images);
  Predict(advance_images);
  ApplyIndexLimits();
  return Peak();
}

Localization MarkovLocalizer::Update(const Eigen::MatrixXf& projections,
                                     const Eigen::VectorXf& query, double advance_images) {
  const int n = static_cast<int>(projections.cols());
  if (n == 0) return {};
  PredictFor(n, advance_images);
  return Correct(n, NearestProjections(projections, query, options_.kernels));
}

Localization MarkovLocalizer::Update(const Eigen::MatrixXf& projections,
                                     const std::vector<int>& column_place, int places,
                                     const Eigen::VectorXf& query, double advance_images) {
  if (places == 0 || projections.cols() == 0) return {};
  PredictFor(places, advance_images);
  return Correct(places, NearestPlaces(projections, column_place, places, query, options_.kernels));
}

void MarkovLocalizer::PredictFor(int n, double advance_images) {
  MAPLESS_CHECK(std::isfinite(advance_images),
                "Markov localization: advance = " << advance_images << "; must be finite");
  if (belief_.size() == 0) ResetUniform(n);
  MAPLESS_CHECK(n >= belief_.size(), "Markov localization: the route shrank from "
                                         << belief_.size() << " to " << n << " images");
  Grow(n);
  Predict(advance_images);
  ApplyIndexLimits();
}

Localization MarkovLocalizer::Correct(int n, std::vector<Neighbour> neighbours) {
  Localization result;
  // Eq. (6): p(z|x) = 1/k Σ γ_j exp(-((x - x_j)/σ)²), γ_j = d_1 / d_j in (0, 1].
  result.neighbours = std::move(neighbours);
  const double sigma = options_.kernel_sigma_images;
  const int reach = static_cast<int>(std::ceil(4.0 * sigma));
  const double nearest = result.neighbours.front().distance;
  const double k = static_cast<double>(result.neighbours.size());
  scratch_ = Eigen::VectorXd::Constant(n, options_.observation_floor);
  for (const Neighbour& neighbour : result.neighbours) {
    const double gamma = neighbour.distance > 0.0F ? nearest / neighbour.distance : 1.0;
    for (int x = std::max(0, neighbour.index - reach);
         x <= std::min(n - 1, neighbour.index + reach); ++x) {
      const double z = (x - neighbour.index) / sigma;
      scratch_(x) += gamma * std::exp(-z * z) / k;
    }
  }
  result.agreement = belief_.dot(scratch_) / scratch_.maxCoeff();
  belief_ = belief_.cwiseProduct(scratch_);  // Eq. (5)
  const double total = belief_.sum();
  if (!(total > 0.0) || !std::isfinite(total)) {
    ResetUniform(n);
  } else {
    belief_ /= total;
  }

  const Localization peak = Peak();
  result.index = peak.index;
  result.probability = peak.probability;
  const bool doubtful =
      result.probability < options_.lost_probability || result.agreement < options_.min_agreement;
  low_updates_ = doubtful ? low_updates_ + 1 : 0;
  result.status = low_updates_ >= options_.lost_after_updates ? LocalizationStatus::kLost
                                                              : LocalizationStatus::kTracking;
  return result;
}

}  // namespace mapless::localization

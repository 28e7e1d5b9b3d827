#include "mapless/localization/initial.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mapless/core/check.h"

namespace mapless::localization {

void ClusteringOptions::Validate() const {
  MAPLESS_CHECK(join_distance_images > 0.0, "ClusteringOptions.join_distance_images = "
                                                << join_distance_images << "; must be > 0");
  MAPLESS_CHECK(
      min_member_fraction >= 0.0 && min_member_fraction <= 1.0,
      "ClusteringOptions.min_member_fraction = " << min_member_fraction << "; must be in [0, 1]");
}

InitialLocalization LocalizeByClustering(const std::vector<int>& localizations,
                                         const ClusteringOptions& options) {
  options.Validate();
  InitialLocalization result;
  if (localizations.empty()) {
    result.reason = "no images to localize";
    return result;
  }
  for (const int index : localizations) {
    int nearest = -1;
    double nearest_distance = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < result.clusters.size(); ++c) {
      const double d = std::abs(index - result.clusters[c].centre);
      if (d < nearest_distance) {
        nearest_distance = d;
        nearest = static_cast<int>(c);
      }
    }
    if (nearest < 0 || nearest_distance > options.join_distance_images) {
      result.clusters.push_back({static_cast<double>(index), {index}, 0.0});
      continue;
    }
    Cluster& cluster = result.clusters[static_cast<std::size_t>(nearest)];
    cluster.members.push_back(index);
    double sum = 0.0;
    for (const int m : cluster.members) sum += m;
    cluster.centre = sum / static_cast<double>(cluster.members.size());
  }
  std::size_t largest = 0;
  for (const Cluster& cluster : result.clusters)
    largest = std::max(largest, cluster.members.size());
  const double min_members = options.min_member_fraction * static_cast<double>(largest);
  double best_variance = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < result.clusters.size(); ++c) {
    Cluster& cluster = result.clusters[c];
    double sum = 0.0;
    for (const int m : cluster.members) sum += (m - cluster.centre) * (m - cluster.centre);
    cluster.variance = sum / static_cast<double>(cluster.members.size());
    if (static_cast<double>(cluster.members.size()) < min_members || cluster.members.size() < 2) {
      continue;
    }
    const bool better =
        cluster.variance < best_variance ||
        (cluster.variance == best_variance &&
         cluster.members.size() >
             result.clusters[static_cast<std::size_t>(result.chosen)].members.size());
    if (better) {
      best_variance = cluster.variance;
      result.chosen = static_cast<int>(c);
    }
  }
  if (result.chosen < 0) {
    result.reason = "no cluster with enough members among " +
                    std::to_string(result.clusters.size()) + " clusters of " +
                    std::to_string(localizations.size()) + " localizations";
    return result;
  }
  result.ok = true;
  result.index = static_cast<int>(
      std::lround(result.clusters[static_cast<std::size_t>(result.chosen)].centre));
  return result;
}

}  // namespace mapless::localization

#include "mapless/localization/nearest.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"

namespace mapless::localization {

std::vector<Neighbour> NearestProjections(const Eigen::MatrixXf& projections,
                                          const Eigen::VectorXf& query, int k) {
  MAPLESS_CHECK(k >= 1, "nearest projections: k = " << k << "; must be >= 1");
  MAPLESS_CHECK(projections.rows() == query.size(), "nearest projections: query of "
                                                        << query.size() << " components, route of "
                                                        << projections.rows());
  const int n = static_cast<int>(projections.cols());
  std::vector<Neighbour> all(static_cast<std::size_t>(n));
  const Eigen::VectorXf squared = (projections.colwise() - query).colwise().squaredNorm();
  for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = {i, squared(i)};
  const auto nearer = [](const Neighbour& a, const Neighbour& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.index < b.index;
  };
  const std::size_t keep = std::min(all.size(), static_cast<std::size_t>(k));
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(keep), all.end(),
                    nearer);
  all.resize(keep);
  for (Neighbour& neighbour : all) neighbour.distance = std::sqrt(neighbour.distance);
  return all;
}

Neighbour NearestProjection(const Eigen::MatrixXf& projections, const Eigen::VectorXf& query) {
  if (projections.cols() == 0) return {};
  return NearestProjections(projections, query, 1).front();
}

}  // namespace mapless::localization

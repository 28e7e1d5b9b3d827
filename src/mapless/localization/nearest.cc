#include "mapless/localization/nearest.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mapless/core/check.h"

namespace mapless::localization {
namespace {

// The k nearest of `all` (squared distances), nearest first, ties broken by the lower index; the
// distances made Euclidean.
void KeepNearest(std::vector<Neighbour>* all, int k) {
  const auto nearer = [](const Neighbour& a, const Neighbour& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.index < b.index;
  };
  const std::size_t keep = std::min(all->size(), static_cast<std::size_t>(k));
  std::partial_sort(all->begin(), all->begin() + static_cast<std::ptrdiff_t>(keep), all->end(),
                    nearer);
  all->resize(keep);
  for (Neighbour& neighbour : *all) neighbour.distance = std::sqrt(neighbour.distance);
}

}  // namespace

std::vector<Neighbour> NearestProjections(const Eigen::MatrixXf& projections,
                                          const Eigen::VectorXf& query, int k) {
  MAPLESS_CHECK(k >= 1, "nearest projections: k = " << k << "; must be >= 1");
  MAPLESS_CHECK(projections.rows() == query.size(), "nearest projections: query of "
                                                        << query.size() << " components, route of "
                                                        << projections.rows());
  const int n = static_cast<int>(projections.cols());
  std::vector<Neighbour> all(static_cast<std::size_t>(n));
  const Eigen::VectorXf squared = (projections.colwise() - query).colwise().squaredNorm();
  for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = {i, squared(i), i};
  KeepNearest(&all, k);
  return all;
}

std::vector<Neighbour> NearestPlaces(const Eigen::MatrixXf& projections,
                                     const std::vector<int>& column_place, int places,
                                     const Eigen::VectorXf& query, int k) {
  MAPLESS_CHECK(k >= 1, "nearest places: k = " << k << "; must be >= 1");
  MAPLESS_CHECK(projections.rows() == query.size(), "nearest places: query of "
                                                        << query.size() << " components, route of "
                                                        << projections.rows());
  MAPLESS_CHECK(column_place.size() == static_cast<std::size_t>(projections.cols()),
                "nearest places: " << column_place.size() << " places for " << projections.cols()
                                   << " columns");
  std::vector<Neighbour> all(static_cast<std::size_t>(std::max(places, 0)));
  for (int p = 0; p < places; ++p)
    all[static_cast<std::size_t>(p)] = {p, std::numeric_limits<float>::infinity(), -1};
  const Eigen::VectorXf squared = (projections.colwise() - query).colwise().squaredNorm();
  for (Eigen::Index c = 0; c < projections.cols(); ++c) {
    const int p = column_place[static_cast<std::size_t>(c)];
    MAPLESS_CHECK(p >= 0 && p < places, "nearest places: column " << c << " of place " << p);
    Neighbour& best = all[static_cast<std::size_t>(p)];
    if (squared(c) < best.distance) best = {p, squared(c), static_cast<int>(c)};
  }
  all.erase(std::remove_if(all.begin(), all.end(), [](const Neighbour& n) { return n.column < 0; }),
            all.end());
  KeepNearest(&all, k);
  return all;
}

Neighbour NearestProjection(const Eigen::MatrixXf& projections, const Eigen::VectorXf& query) {
  if (projections.cols() == 0) return {};
  return NearestProjections(projections, query, 1).front();
}

}  // namespace mapless::localization

// Auto-localization by the nearest projection (Section 3 of Payá et al.): the current image is
// projected into the route's eigenspace and compared with every stored projection; the one at the
// smallest Euclidean distance is the robot's position on the route.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace mapless::localization {

struct Neighbour {
  int index = -1;         // route image (column of the projections), or place (NearestPlaces)
  float distance = 0.0F;  // Euclidean distance in the eigenspace
  int column = -1;        // the column that gave it (index, for NearestProjections)
};

// The `k` stored projections (columns of `projections`, K x N) nearest to `query` (K), nearest
// first; ties broken by the lower index. Fewer when N < k.
std::vector<Neighbour> NearestProjections(const Eigen::MatrixXf& projections,
                                          const Eigen::VectorXf& query, int k);

// A route whose places have several images (learned views, issue 45): the `k` places nearest to
// `query`, a place's distance being its nearest column's (`column_place[c]` is the place of
// column c, in [0, places)); nearest first, ties broken by the lower place. With one column per
// place in place order, the same as NearestProjections.
std::vector<Neighbour> NearestPlaces(const Eigen::MatrixXf& projections,
                                     const std::vector<int>& column_place, int places,
                                     const Eigen::VectorXf& query, int k);

// The nearest one; index -1 when the route is empty.
Neighbour NearestProjection(const Eigen::MatrixXf& projections, const Eigen::VectorXf& query);

}  // namespace mapless::localization

// Auto-localization by the nearest projection (Section 3 of Payá et al.): the current image is
// projected into the route's eigenspace and compared with every stored projection; the one at the
// smallest Euclidean distance is the robot's position on the route.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace mapless::localization {

struct Neighbour {
  int index = -1;         // route image (column of the projections)
  float distance = 0.0F;  // Euclidean distance in the eigenspace
};

// The `k` stored projections (columns of `projections`, K x N) nearest to `query` (K), nearest
// first; ties broken by the lower index. Fewer when N < k.
std::vector<Neighbour> NearestProjections(const Eigen::MatrixXf& projections,
                                          const Eigen::VectorXf& query, int k);

// The nearest one; index -1 when the route is empty.
Neighbour NearestProjection(const Eigen::MatrixXf& projections, const Eigen::VectorXf& query);

}  // namespace mapless::localization

// The eigen-system of a diagonal matrix plus a rank-one term, diag(d) + rho z z^T (rho > 0): the
// update step of the incremental PCA (pca.cc, Eq. 3) in O(k^2) instead of a general symmetric
// solver's O(k^3) (issue 44). The classic method: deflation of negligible components and of nearly
// equal diagonal entries (Givens rotations), the secular equation 1 + rho sum z_j^2 / (d_j - mu) =
// 0 solved for each eigenvalue in its interval, and eigenvectors from the recomputed z of Gu and
// Eisenstat (1994), which keeps them orthogonal to working precision. LAPACK's dlaed2/dlaed3/dlaed4
// do the same.
#pragma once

#include <Eigen/Core>

namespace mapless::appearance {

struct RankOneEigen {
  Eigen::VectorXd values;   // decreasing
  Eigen::MatrixXd vectors;  // column i belongs to values(i); orthonormal
};

// Sizes must agree and rho must be positive (checked).
RankOneEigen RankOneUpdateEigen(const Eigen::VectorXd& d, double rho, const Eigen::VectorXd& z);

}  // namespace mapless::appearance

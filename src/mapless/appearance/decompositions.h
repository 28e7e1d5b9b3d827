// The dense matrix decompositions the appearance module uses, from Eigen, in a translation unit of
// their own. Eigen's solvers are most of this module's compile time (its template instantiations),
// and the sanitizer build compiles this file without instrumentation: they are third-party
// numerical kernels, and the module's own code around them (the incremental PCA's growing
// buffers, the rank-one solver) stays checked (src/mapless/appearance/CMakeLists.txt).
#pragma once

#include <Eigen/Core>

namespace mapless::appearance {

// Thin SVD of `a` (Eigen's BDCSVD, thin U and V computed): U (rows x min(rows, cols)) and the
// singular values, decreasing.
void ThinSvd(const Eigen::MatrixXf& a, Eigen::MatrixXf* u, Eigen::VectorXf* singular_values);

// Full SVD of `a` by one-sided Jacobi rotations (Eigen's JacobiSVD, full U and V): the slow,
// accurate reference, a = U diag(s) Vᵀ.
void JacobiSvd(const Eigen::MatrixXd& a, Eigen::MatrixXd* u, Eigen::VectorXd* singular_values,
               Eigen::MatrixXd* v);

// Eigen-decomposition of a symmetric matrix (Eigen's SelfAdjointEigenSolver; only the lower
// triangle is read): eigenvalues increasing, unit eigenvectors as columns in the same order.
void SymmetricEigen(const Eigen::MatrixXd& a, Eigen::VectorXd* values, Eigen::MatrixXd* vectors);

// The first v.cols() columns of the Q of v's Householder QR: an orthonormal basis of v's columns
// (up to the sign of each).
Eigen::MatrixXf ThinQ(const Eigen::MatrixXf& v);

}  // namespace mapless::appearance

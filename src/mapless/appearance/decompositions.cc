#include "mapless/appearance/decompositions.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

namespace mapless::appearance {

void ThinSvd(const Eigen::MatrixXf& a, Eigen::MatrixXf* u, Eigen::VectorXf* singular_values) {
  const Eigen::BDCSVD<Eigen::MatrixXf> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
  *u = svd.matrixU();
  *singular_values = svd.singularValues();
}

void JacobiSvd(const Eigen::MatrixXd& a, Eigen::MatrixXd* u, Eigen::VectorXd* singular_values,
               Eigen::MatrixXd* v) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  *u = svd.matrixU();
  *singular_values = svd.singularValues();
  *v = svd.matrixV();
}

void SymmetricEigen(const Eigen::MatrixXd& a, Eigen::VectorXd* values, Eigen::MatrixXd* vectors) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(a);
  *values = solver.eigenvalues();
  *vectors = solver.eigenvectors();
}

Eigen::MatrixXf ThinQ(const Eigen::MatrixXf& v) {
  const Eigen::HouseholderQR<Eigen::MatrixXf> qr(v);
  return qr.householderQ() * Eigen::MatrixXf::Identity(v.rows(), v.cols());
}

}  // namespace mapless::appearance

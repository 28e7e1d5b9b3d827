#include "mapless/appearance/rank_one_eigen.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mapless/appearance/decompositions.h"

namespace mapless::appearance {
namespace {

// Against Eigen's general symmetric solver, on the shapes the incremental PCA makes (eigenvalues
// spread over decades, a zero for the new dimension) and the degenerate ones deflation handles
// (equal diagonal entries, zero and negligible components).
TEST(RankOneUpdateEigen, MatchesTheGeneralSolverAndStaysOrthonormal) {
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss;
  for (int trial = 0; trial < 200; ++trial) {
    const int m = 1 + trial % 97;
    Eigen::VectorXd d(m), z(m);
    for (int i = 0; i < m; ++i) {
      d(i) = std::exp(3.0 * gauss(rng));
      z(i) = gauss(rng);
    }
    if (trial % 3 == 0 && m > 2) d(m - 1) = 0.0;  // the new dimension
    if (trial % 5 == 0 && m > 3) d(1) = d(2);     // a tie
    if (trial % 7 == 0 && m > 3) {
      z(0) = 0.0;
      z(2) = 1e-18;
    }
    const double rho = std::exp(gauss(rng));
    const Eigen::MatrixXd D = Eigen::MatrixXd(d.asDiagonal()) + rho * z * z.transpose();
    const RankOneEigen e = RankOneUpdateEigen(d, rho, z);
    Eigen::VectorXd general_values;  // Eigen's general solver, increasing
    Eigen::MatrixXd general_vectors;
    SymmetricEigen(D, &general_values, &general_vectors);
    const double scale = D.norm();
    ASSERT_EQ(e.values.size(), m);
    EXPECT_LT((e.values - general_values.reverse()).cwiseAbs().maxCoeff(), 1e-13 * scale)
        << "trial " << trial;
    EXPECT_LT((D * e.vectors - e.vectors * e.values.asDiagonal()).norm(), 1e-13 * scale)
        << "trial " << trial;
    EXPECT_LT((e.vectors.transpose() * e.vectors - Eigen::MatrixXd::Identity(m, m)).norm(), 1e-12)
        << "trial " << trial;
    for (int i = 1; i < m; ++i) EXPECT_GE(e.values(i - 1), e.values(i)) << "trial " << trial;
  }
}

TEST(RankOneUpdateEigen, WithoutTheRankOneTermItIsTheSortedDiagonal) {
  const Eigen::VectorXd d = (Eigen::VectorXd(3) << 1.0, 3.0, 2.0).finished();
  const RankOneEigen e = RankOneUpdateEigen(d, 1.0, Eigen::VectorXd::Zero(3));
  EXPECT_EQ(e.values, (Eigen::VectorXd(3) << 3.0, 2.0, 1.0).finished());
  EXPECT_EQ(e.vectors.col(0), (Eigen::VectorXd(3) << 0.0, 1.0, 0.0).finished());
  EXPECT_THROW(RankOneUpdateEigen(d, 0.0, d), std::exception);
  EXPECT_THROW(RankOneUpdateEigen(d, 1.0, Eigen::VectorXd::Zero(2)), std::exception);
}

}  // namespace
}  // namespace mapless::appearance

#include "mapless/appearance/pca.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mapless/appearance/decompositions.h"
#include "mapless/appearance/image.h"
#include "mapless/core/check.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::appearance {
namespace {

// The first `count` 64x64 images along the office route of the simulator, every second frame
// (doors and posters repeat): the test fixture for the eigenspace, real route images, not random
// vectors. The drive stops once it has them: a test that needs 5 images renders 10 frames.
Matrix RouteImages(int count) {
  const sim::Scenario scenario = sim::LoadScenario("office_aliasing");
  std::vector<Vector> images;
  sim::DriveOptions options;
  options.seed = 3;
  struct Enough {};
  try {
    sim::DriveTaughtPath(scenario, options, [&](const sim::DriveFrame& frame) {
      if (frame.index % 2 == 0) images.push_back(AppearanceVector(frame.image, {}));
      if (static_cast<int>(images.size()) == count) throw Enough{};
    });
  } catch (const Enough&) {
  }
  EXPECT_GE(static_cast<int>(images.size()), count);
  Matrix data(images.front().size(), count);
  for (int i = 0; i < count; ++i) data.col(i) = images[static_cast<std::size_t>(i)];
  return data;
}

const Matrix& Route300() {
  static const Matrix data = RouteImages(300);
  return data;
}

// Orthogonal Procrustes: the relative residual of the best rotation (and reflection) taking the
// columns of `a` onto those of `b`; 0 when they agree up to sign and rotation.
double ProcrustesResidual(const Matrix& a, const Matrix& b) {
  Eigen::MatrixXd u, v;
  Eigen::VectorXd s;
  JacobiSvd((b * a.transpose()).cast<double>(), &u, &s, &v);
  const Eigen::MatrixXd omega = u * v.transpose();
  return (omega * a.cast<double>() - b.cast<double>()).norm() / b.cast<double>().norm();
}

TEST(BatchPca, SvdAndTurkPentlandAgree) {
  const Matrix data = RouteImages(80);
  const Eigenspace svd = BatchPcaSvd(data, 20);
  const Eigenspace gram = BatchPcaGram(data, 20);
  ASSERT_EQ(svd.dimensions(), 20);
  ASSERT_EQ(gram.dimensions(), 20);
  for (int i = 0; i < 20; ++i) {
    EXPECT_NEAR(svd.eigenvalues(i), gram.eigenvalues(i), 1e-3 * svd.eigenvalues(0)) << i;
    // Same eigenvector up to sign.
    EXPECT_GT(std::abs(svd.basis.col(i).dot(gram.basis.col(i))), 0.99F) << i;
  }
  for (int j = 0; j < data.cols(); ++j) {
    EXPECT_NEAR(svd.ReconstructionError(data.col(j)), gram.ReconstructionError(data.col(j)),
                1e-3F * data.col(j).norm());
  }
}

TEST(BatchPca, KeepsNoMoreDimensionsThanTheImagesSpan) {
  const Matrix data = RouteImages(5);
  EXPECT_EQ(BatchPcaSvd(data, 50).dimensions(), 4);
  EXPECT_EQ(BatchPcaGram(data, 50).dimensions(), 4);
}

TEST(IncrementalPca, IsExactWhenNoDimensionIsDropped) {
  const Matrix data = RouteImages(40);
  IncrementalPcaOptions options;
  options.max_dimensions = 100;
  options.extra_dimensions = 0;
  options.min_eigenvalue_ratio = 0.0;
  options.min_relative_residual = 0.0;
  IncrementalPca pca(options);
  for (int j = 0; j < data.cols(); ++j) pca.Add(data.col(j));
  const Eigenspace batch = BatchPcaSvd(data, 39);
  const Eigenspace inc = pca.Model();
  ASSERT_EQ(inc.dimensions(), 39);
  EXPECT_LT((inc.mean - batch.mean).norm(), 1e-4F * batch.mean.norm() + 1e-4F);
  for (int i = 0; i < 10; ++i) {
    EXPECT_NEAR(inc.eigenvalues(i), batch.eigenvalues(i), 1e-3 * batch.eigenvalues(0)) << i;
  }
  EXPECT_LT(ProcrustesResidual(inc.projections, batch.projections), 1e-3);
  // The stored projections are those of the current model (Eq. 4 keeps them up to date).
  for (int j = 0; j < data.cols(); ++j) {
    EXPECT_LT((inc.Project(data.col(j)) - inc.projections.col(j)).norm(),
              1e-3F * data.col(j).norm());
  }
}

// The acceptance test of the issue: N = 300 route images added one at a time with the
// dimension criteria active, against batch PCA with the same K.
TEST(IncrementalPca, MatchesBatchPcaOn300RouteImages) {
  const Matrix& data = Route300();
  IncrementalPca pca;  // default options: K = 16 (kept among 96) and both dimension criteria
  for (int j = 0; j < data.cols(); ++j) pca.Add(data.col(j));
  const Eigenspace inc = pca.Model();
  const int k = inc.dimensions();
  ASSERT_GE(k, 10);
  const Eigenspace batch = BatchPcaSvd(data, k);
  ASSERT_EQ(batch.dimensions(), k);
  double worst_relative = 0.0;
  for (int j = 0; j < data.cols(); ++j) {
    const double e_inc = inc.ReconstructionError(data.col(j));
    const double e_batch = batch.ReconstructionError(data.col(j));
    worst_relative = std::max(worst_relative, std::abs(e_inc - e_batch) / e_batch);
  }
  RecordProperty("worst_relative_reconstruction_difference", std::to_string(worst_relative));
  std::printf("K = %d, worst relative reconstruction difference %.4f\n", k, worst_relative);
  EXPECT_LE(worst_relative, 0.01);
  const double procrustes = ProcrustesResidual(inc.projections, batch.projections);
  std::printf("projections: Procrustes residual %.4f\n", procrustes);
  // Not a number the issue gives: the top-K subspaces differ slightly, so the projections agree
  // up to rotation within a few percent (2.8% measured).
  EXPECT_LT(procrustes, 0.05);
}

TEST(IncrementalPca, ProjectionOfANewImageMatchesTheModel) {
  const Matrix& data = Route300();
  IncrementalPca pca;
  for (int j = 0; j < 100; ++j) pca.Add(data.col(j));
  const Eigenspace model = pca.Model();
  const Vector x = data.col(150);
  EXPECT_LT((pca.Project(x) - model.Project(x)).norm(), 1e-4F * x.norm());
  // The basis stays orthonormal through rotations and folds.
  const Matrix gram = model.basis.transpose() * model.basis;
  EXPECT_LT((gram - Matrix::Identity(gram.rows(), gram.cols())).norm(), 1e-3F);
}

TEST(IncrementalPca, AcceptsRepeatedIdenticalImages) {
  IncrementalPca pca;
  pca.Add(Vector::Ones(16));
  pca.Add(Vector::Ones(16));  // no residual and no eigenvector yet
  EXPECT_EQ(pca.dimensions(), 0);
  Vector other = Vector::Ones(16);
  other(3) = 5.0F;
  pca.Add(other);
  EXPECT_EQ(pca.dimensions(), 1);
  EXPECT_EQ(pca.Model().images(), 3);
}

TEST(IncrementalPca, RejectsAnImageOfAnotherSize) {
  IncrementalPca pca;
  pca.Add(Vector::Ones(16));
  EXPECT_THROW(pca.Add(Vector::Ones(17)), InputError);
  IncrementalPcaOptions bad;
  bad.max_dimensions = 0;
  EXPECT_THROW(IncrementalPca{bad}, InputError);
}

}  // namespace
}  // namespace mapless::appearance

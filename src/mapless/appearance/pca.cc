#include "mapless/appearance/pca.h"

#include <algorithm>
#include <cmath>

#include "mapless/appearance/decompositions.h"
#include "mapless/appearance/rank_one_eigen.h"
#include "mapless/core/check.h"

namespace mapless::appearance {
namespace {

// Keeps the first `k` columns of an eigen decomposition sorted by decreasing eigenvalue, dropping
// components without variance.
int UsableDimensions(const Vector& sorted_eigenvalues, int requested) {
  int k = std::min<int>(requested, static_cast<int>(sorted_eigenvalues.size()));
  const float floor =
      sorted_eigenvalues.size() > 0 ? 1e-7F * std::max(sorted_eigenvalues(0), 0.0F) : 0.0F;
  while (k > 0 && !(sorted_eigenvalues(k - 1) > floor)) --k;
  return k;
}

void CheckImages(const Matrix& images, int dimensions) {
  MAPLESS_CHECK(images.cols() >= 1 && images.rows() >= 1,
                "PCA needs at least one image of at least one pixel, got " << images.rows() << " x "
                                                                           << images.cols());
  MAPLESS_CHECK(dimensions >= 0, "PCA dimensions = " << dimensions << "; must be >= 0");
}

}  // namespace

Vector Eigenspace::Project(const Vector& image) const { return basis.transpose() * (image - mean); }

Vector Eigenspace::Reconstruct(const Vector& projection) const { return basis * projection + mean; }

float Eigenspace::ReconstructionError(const Vector& image) const {
  return (image - Reconstruct(Project(image))).norm();
}

Eigenspace BatchPcaSvd(const Matrix& images, int dimensions) {
  CheckImages(images, dimensions);
  Eigenspace space;
  space.mean = images.rowwise().mean();
  const Matrix centred = images.colwise() - space.mean;
  Matrix u;
  Vector singular_values;
  ThinSvd(centred, &u, &singular_values);
  const Vector eigenvalues = singular_values.array().square() / static_cast<float>(images.cols());
  const int k = UsableDimensions(eigenvalues, dimensions);
  space.basis = u.leftCols(k);
  space.eigenvalues = eigenvalues.head(k);
  space.projections = space.basis.transpose() * centred;
  return space;
}

Eigenspace BatchPcaGram(const Matrix& images, int dimensions) {
  CheckImages(images, dimensions);
  Eigenspace space;
  space.mean = images.rowwise().mean();
  const Matrix centred = images.colwise() - space.mean;
  // Turk & Pentland: if (AᵀA) w = μ w then (A Aᵀ)(A w) = μ (A w); ‖A w‖ = sqrt(μ).
  const Eigen::MatrixXd gram = (centred.transpose() * centred).cast<double>();
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
  SymmetricEigen(gram, &values, &vectors);
  const int n = static_cast<int>(gram.rows());
  Vector eigenvalues(n);
  for (int i = 0; i < n; ++i) {
    eigenvalues(i) = static_cast<float>(values(n - 1 - i) / images.cols());
  }
  const int k = UsableDimensions(eigenvalues, dimensions);
  space.basis.resize(images.rows(), k);
  for (int i = 0; i < k; ++i) {
    const Vector w = vectors.col(n - 1 - i).cast<float>();
    space.basis.col(i) = (centred * w).normalized();
  }
  space.eigenvalues = eigenvalues.head(k);
  space.projections = space.basis.transpose() * centred;
  return space;
}

void IncrementalPcaOptions::Validate() const {
  MAPLESS_CHECK(max_dimensions >= 1,
                "IncrementalPcaOptions.max_dimensions = " << max_dimensions << "; must be >= 1");
  MAPLESS_CHECK(extra_dimensions >= 0, "IncrementalPcaOptions.extra_dimensions = "
                                           << extra_dimensions << "; must be >= 0");
  MAPLESS_CHECK(min_eigenvalue_ratio >= 0.0 && min_eigenvalue_ratio < 1.0,
                "IncrementalPcaOptions.min_eigenvalue_ratio = " << min_eigenvalue_ratio
                                                                << "; must be in [0, 1)");
  MAPLESS_CHECK(min_relative_residual >= 0.0 && min_relative_residual < 1.0,
                "IncrementalPcaOptions.min_relative_residual = " << min_relative_residual
                                                                 << "; must be in [0, 1)");
}

IncrementalPca::IncrementalPca(IncrementalPcaOptions options) : options_(options) {
  options_.Validate();
}

Vector IncrementalPca::Project(const Vector& image) const {
  MAPLESS_CHECK(n_ > 0 && image.size() == mean_.size(), "IncrementalPca::Project: image of "
                                                            << image.size() << " pixels, model of "
                                                            << mean_.size());
  const Vector all = q_.transpose() * (U().transpose() * (image - mean_));
  return all.head(dimensions());
}

int IncrementalPca::dimensions() const {
  return std::min(static_cast<int>(q_.cols()), options_.max_dimensions);
}

void IncrementalPca::Add(const Vector& image) {
  if (n_ == 0) {
    MAPLESS_CHECK(image.size() >= 1, "IncrementalPca::Add: empty image");
    mean_ = image;
    u_.resize(image.size(), 0);
    u_cols_ = 0;
    q_.resize(0, 0);
    eigenvalues_.resize(0);
    stored_rows_ = 0;
    stored_.resize(0, 0);
    ReserveStored(0, 1);
    transform_.resize(0, 0);
    offset_.resize(0);
    n_ = 1;
    return;
  }
  MAPLESS_CHECK(image.size() == mean_.size(), "IncrementalPca::Add: image of "
                                                  << image.size() << " pixels, the eigenspace has "
                                                  << mean_.size());
  const int k = static_cast<int>(q_.cols());
  const double n = n_;
  const Vector d = image - mean_;  // x_{N+1} - m
  const Vector up = U().transpose() * d;
  const Vector p = q_.transpose() * up;  // Vᵀ(x - m)
  // Residual h = (x - m) - V p, orthogonal to V; a second pass keeps it so in floating point.
  Vector h = d;
  if (k > 0) {
    const Vector qp = q_ * p;
    h.noalias() -= U() * qp;
    const Vector uh = U().transpose() * h;
    const Vector qqh = q_ * (q_.transpose() * uh);
    h.noalias() -= U() * qqh;
  }
  const double h_norm = h.norm();
  const double d_norm = d.norm();
  const bool add_dimension = h_norm > options_.min_relative_residual * d_norm && h_norm > 1e-12;

  // Eq. (3): D = N/(N+1) [Λ 0; 0 0] + N/(N+1)² [p pᵀ, δp; δpᵀ, δ²], δ = ĥᵀ(x - m) = ‖h‖.
  const int k1 = add_dimension ? k + 1 : k;
  if (k1 == 0) {  // the same image as the mean so far: nothing to rotate
    mean_ = (mean_ * static_cast<float>(n) + image) / static_cast<float>(n + 1.0);
    ReserveStored(stored_rows_, n_ + 1);
    stored_.col(n_).head(stored_rows_).setZero();
    transform_.resize(0, stored_rows_);
    offset_.resize(0);
    ++n_;
    return;
  }
  Eigen::VectorXd a(k1);
  a.head(k) = p.cast<double>();
  if (add_dimension) a(k) = h_norm;
  // D is diagonal plus rank one: its eigen-system in O(k^2) (rank_one_eigen.h; a general
  // symmetric solver took half of Add's time at k = 96). Sorted by decreasing eigenvalue.
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(k1);
  diagonal.head(k) = eigenvalues_.cast<double>() * (n / (n + 1.0));
  const RankOneEigen solved = RankOneUpdateEigen(diagonal, n / ((n + 1.0) * (n + 1.0)), a);
  const Eigen::MatrixXd& R = solved.vectors;
  const Eigen::VectorXd& lambda = solved.values;
  // Dimension criteria: at most max_dimensions; drop trailing eigenvectors whose eigenvalue is
  // below min_eigenvalue_ratio of the first (or carries no variance).
  int keep = std::min(k1, options_.max_dimensions + options_.extra_dimensions);
  while (keep > 0 && (lambda(keep - 1) <= 1e-12 * std::max(lambda(0), 1e-30) ||
                      lambda(keep - 1) < options_.min_eigenvalue_ratio * lambda(0))) {
    --keep;
  }
  const Eigen::MatrixXf r = R.leftCols(keep).cast<float>();

  // Eq. (2): V' = [V ĥ] R, kept factored: U' = [U ĥ], Q' = blkdiag(Q, 1) R.
  if (add_dimension) {
    const Eigen::Index l = u_cols_;
    // U grows in place (its spare columns doubling), not by a copy of M x L floats per image.
    if (l == u_.cols()) u_.conservativeResize(Eigen::NoChange, std::max<Eigen::Index>(8, 2 * l));
    u_.col(l) = h / static_cast<float>(h_norm);
    ++u_cols_;
    Matrix q = Matrix::Zero(l + 1, k + 1);
    q.topLeftCorner(l, k) = q_;
    q(l, k) = 1.0F;
    q_ = q * r;
  } else {
    q_ = q_ * r;
  }
  eigenvalues_ = lambda.head(keep).cast<float>();

  // Eq. (4) (Artac et al.): p_i' = Rᵀ [p_i; 0] + V'ᵀ(m - m'), with m - m' = -(x - m)/(N+1) and
  // V'ᵀ(x - m) = Rᵀ a, so no M-sized product is needed. The new image: V'ᵀ(x - m') = N/(N+1) Rᵀ a.
  // With P = G S + c 1ᵀ (pca.h) the rotation of every stored projection is one of G and c.
  const Vector rta = r.transpose() * a.cast<float>();
  if (add_dimension) {  // [P; 0] = [G 0; 0 1] [S; 0] + [c; 0] 1ᵀ: S gains a row of zeros
    ReserveStored(stored_rows_ + 1, n_ + 1);
    stored_.row(stored_rows_).head(n_).setZero();
    Matrix g = Matrix::Zero(k + 1, stored_rows_ + 1);
    g.topLeftCorner(k, stored_rows_) = transform_;
    g(k, stored_rows_) = 1.0F;
    ++stored_rows_;
    transform_.noalias() = r.transpose() * g;
    offset_ = r.topRows(k).transpose() * offset_;
  } else {
    ReserveStored(stored_rows_, n_ + 1);
    const Matrix g = transform_;
    transform_.noalias() = r.transpose() * g;
    offset_ = r.transpose() * Vector(offset_);
  }
  offset_ -= rta / static_cast<float>(n + 1.0);
  // The new image's stored column: G has orthonormal rows, so G Gᵀ (v - c) = v - c.
  const Vector v = rta * static_cast<float>(n / (n + 1.0));
  stored_.col(n_).head(stored_rows_).noalias() = transform_.transpose() * (v - offset_);
  if (stored_rows_ > 2 * std::max<Eigen::Index>(keep, 4)) FoldProjections(n_ + 1);

  mean_ = (mean_ * static_cast<float>(n) + image) / static_cast<float>(n + 1.0);  // Eq. (1)
  ++n_;
  if (u_cols_ > 2 * std::max<Eigen::Index>(q_.cols(), 4)) Fold();
}

void IncrementalPca::Fold() {
  // U ← U Q, Q ← I; re-orthonormalise against drift accumulated over many rotations.
  Matrix v = U() * q_;
  Matrix orthonormal = ThinQ(v);
  // Keep each column's direction (QR may flip signs).
  for (Eigen::Index i = 0; i < v.cols(); ++i) {
    if (orthonormal.col(i).dot(v.col(i)) < 0.0F) orthonormal.col(i) *= -1.0F;
  }
  u_cols_ = orthonormal.cols();
  u_.leftCols(u_cols_) = orthonormal;
  q_ = Matrix::Identity(u_cols_, u_cols_);
}

Eigenspace IncrementalPca::Model() const {
  const int k = dimensions();
  Eigenspace space;
  space.mean = mean_;
  space.basis = U() * q_.leftCols(k);
  space.eigenvalues = eigenvalues_.head(k);
  space.projections = transform_.topRows(k) * stored_.topLeftCorner(stored_rows_, n_);
  space.projections.colwise() += offset_.head(k);
  return space;
}

void IncrementalPca::ReserveStored(Eigen::Index rows, Eigen::Index cols) {
  if (rows <= stored_.rows() && cols <= stored_.cols()) return;
  // Room for the rows of twice the kept dimensions and twice the images (amortised O(1) growth).
  const Eigen::Index want_rows =
      std::max<Eigen::Index>(rows, 2 * (options_.max_dimensions + options_.extra_dimensions) + 2);
  const Eigen::Index want_cols = std::max<Eigen::Index>(cols, 2 * stored_.cols());
  stored_.conservativeResize(std::max(want_rows, stored_.rows()),
                             std::max(want_cols, stored_.cols()));
}

void IncrementalPca::FoldProjections(Eigen::Index images) {
  // S ← P, G ← I, c ← 0: S is back to L rows (and G's rows orthonormal again).
  Matrix p = transform_ * stored_.topLeftCorner(stored_rows_, images);
  p.colwise() += offset_;
  stored_rows_ = p.rows();
  stored_.topLeftCorner(stored_rows_, images) = p;
  transform_ = Matrix::Identity(stored_rows_, stored_rows_);
  offset_ = Vector::Zero(stored_rows_);
}

}  // namespace mapless::appearance

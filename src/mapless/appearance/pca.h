// Eigenspaces of route images: batch PCA (SVD, and Turk & Pentland's N x N Gram matrix for
// M >> N) and the incremental PCA of Artac, Jogan & Leonardis (2002) that grows the eigenspace one
// image at a time and keeps every stored projection up to date.
//
// Implements Section 2 of Payá et al., "Probabilistic appearance-based navigation of a mobile
// robot" (../shared/papers/incremental_pca_markov_route_following.md), Eq. (1)-(4).
//
// Conventions: images are column vectors of M floats; the covariance is normalised by N (the
// paper's eigenvalues Λ); projections are p = Vᵀ(x - m). Eigenvectors are sorted by decreasing
// eigenvalue. The sign of each eigenvector is arbitrary (compare projections up to sign).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace mapless::appearance {

using Vector = Eigen::VectorXf;
using Matrix = Eigen::MatrixXf;

// A fitted eigenspace: mean, K orthonormal eigenvectors, their eigenvalues and the projection of
// every image it was built from (one column per image, in the order they were given).
struct Eigenspace {
  Vector mean;         // M
  Matrix basis;        // M x K, orthonormal columns
  Vector eigenvalues;  // K, decreasing
  Matrix projections;  // K x N

  int dimensions() const { return static_cast<int>(basis.cols()); }
  int images() const { return static_cast<int>(projections.cols()); }
  Vector Project(const Vector& image) const;           // Vᵀ(x - m)
  Vector Reconstruct(const Vector& projection) const;  // V p + m
  // ‖x - (V Vᵀ(x - m) + m)‖: how much of the image the eigenspace cannot represent.
  float ReconstructionError(const Vector& image) const;
};

// Batch PCA of the columns of `images` (M x N), keeping the first `dimensions` components
// (at most N - 1 carry variance; fewer are kept when N is smaller). Thin SVD of the centred data.
Eigenspace BatchPcaSvd(const Matrix& images, int dimensions);
// The same through the eigenvectors of the N x N matrix AᵀA (Turk & Pentland 1991): cheaper when
// M >> N, as for 64x64 route images.
Eigenspace BatchPcaGram(const Matrix& images, int dimensions);

struct IncrementalPcaOptions {
  int max_dimensions = 16;  // K: the model reports (and localization uses) at most this many
  // Eigenvectors kept beyond K while images arrive. Truncating to K at every step loses the
  // directions that many new images share but none carries alone (a new stretch of route), so
  // the model keeps K + extra and reports the first K: with 80 extra, the reconstruction error of
  // each of 300 route images is within 0.3% of batch PCA with the same K (pca_test.cc).
  int extra_dimensions = 80;
  // Criterion 1 (Section 2, step 3): after an update, the last eigenvector is dropped when its
  // eigenvalue is below this fraction of the first one. 0 disables it.
  double min_eigenvalue_ratio = 1e-4;
  // Criterion 2: no dimension is added when the residual of the new image, relative to the norm
  // of the image minus the mean, is below this (it is represented well enough already).
  double min_relative_residual = 1e-3;
  void Validate() const;
};

// Artac et al.'s incremental PCA. With L = K + extra kept eigenvectors, Add() costs
// O(M L + L³ + N L) amortised (projections included): the basis is kept factored as V = U Q so
// that the rotation of Eq. (2) touches only the small matrix Q, and the projections likewise
// (below); U is folded back (U ← U Q) when it has grown to twice L columns. The eigen-system of
// Eq. (3) is a diagonal-plus-rank-one one (rank_one_eigen.h).
class IncrementalPca {
 public:
  explicit IncrementalPca(IncrementalPcaOptions options = {});

  // Adds one image (M floats; every image must have the same M) and updates the mean (Eq. 1), the
  // eigenvectors (Eq. 2-3), the eigenvalues and every stored projection (Eq. 4).
  void Add(const Vector& image);

  int images() const { return n_; }
  // K: the reported dimensions (at most max_dimensions of the kept ones).
  int dimensions() const;
  // The current model with its first K eigenvectors (materialises V = U Q; O(M K L)).
  Eigenspace Model() const;
  const Vector& mean() const { return mean_; }
  // Projection of an image that is not added on the first K eigenvectors: Vᵀ(x - m), O(M L)
  // without materialising V.
  Vector Project(const Vector& image) const;

 private:
  void Fold();
  // Room in stored_ for this many rows and images.
  void ReserveStored(Eigen::Index rows, Eigen::Index cols);
  void FoldProjections(Eigen::Index images);

  IncrementalPcaOptions options_;
  int n_ = 0;
  Vector mean_;
  // U, M x L (L >= K, the first u_cols_ columns of u_, the rest spare); V = U Q.
  auto U() const { return u_.leftCols(u_cols_); }
  Matrix u_;
  Eigen::Index u_cols_ = 0;
  Matrix q_;  // L x K
  Vector eigenvalues_;
  // The stored projections (L x N, Eq. 4), kept factored as the basis is (issue 44): P = G S +
  // c 1ᵀ with G's rows orthonormal, so each image's rotation touches G (L x s) and c, not all N
  // projections; S gains a row with each new dimension and a column with each image, and is
  // folded back (S ← P) when it has twice L rows.
  Matrix stored_;  // S: the first stored_rows_ rows and n_ columns are in use
  Eigen::Index stored_rows_ = 0;
  Matrix transform_;  // G: L x stored_rows_
  Vector offset_;     // c: L
};

}  // namespace mapless::appearance

#include "mapless/appearance/rank_one_eigen.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "mapless/core/check.h"

namespace mapless::appearance {
namespace {

struct Givens {
  Eigen::Index p, q;  // rows: x_p = c y_p + s y_q, x_q = -s y_p + c y_q
  double c, s;
};

// One root of 1 + rho sum z_j^2 / (d_j - mu) on (d[i], d[i + 1]) (or (d[k-1], d[k-1] + rho) for
// the last), with z of unit norm and d increasing: mu = d[origin] + tau, origin the nearer end,
// so mu - d_j = (d_j' ...) keeps its relative accuracy near the pole.
void SolveSecular(const std::vector<double>& d, const std::vector<double>& z, double rho,
                  std::size_t i, std::size_t* origin, double* tau) {
  const std::size_t k = d.size();
  const auto f_at = [&](std::size_t o, double t, double* slope) {
    double f = 1.0, g = 0.0;
    for (std::size_t j = 0; j < k; ++j) {
      const double r = z[j] / ((d[j] - d[o]) - t);
      f += rho * z[j] * r;
      g += rho * r * r;
    }
    if (slope != nullptr) *slope = g;
    return f;
  };
  double lo = 0.0, hi = 0.0;
  if (i + 1 < k) {
    const double gap = d[i + 1] - d[i];
    if (f_at(i, 0.5 * gap, nullptr) >= 0.0) {
      *origin = i;
      hi = 0.5 * gap;
    } else {
      *origin = i + 1;
      lo = -0.5 * gap;
    }
  } else {
    *origin = i;
    hi = rho;
  }
  double t = 0.5 * (lo + hi);
  for (int iteration = 0; iteration < 200; ++iteration) {
    double slope = 0.0;
    const double f = f_at(*origin, t, &slope);
    if (f == 0.0) break;
    if (f > 0.0) {
      hi = t;
    } else {
      lo = t;
    }
    double next = slope > 0.0 ? t - f / slope : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const double eps = std::numeric_limits<double>::epsilon();
    const bool converged = std::abs(next - t) <= 2.0 * eps * std::max(std::abs(next), 1e-300) ||
                           hi - lo <= 2.0 * eps * std::max(std::abs(lo), std::abs(hi));
    t = next;
    if (converged) break;
  }
  *tau = t;
}

}  // namespace

RankOneEigen RankOneUpdateEigen(const Eigen::VectorXd& d_in, double rho,
                                const Eigen::VectorXd& z_in) {
  MAPLESS_CHECK(d_in.size() == z_in.size() && d_in.size() >= 1,
                "RankOneUpdateEigen: d and z must be non-empty and of one size");
  MAPLESS_CHECK(rho > 0.0 && std::isfinite(rho), "RankOneUpdateEigen: rho = " << rho);
  const Eigen::Index m = d_in.size();
  std::vector<Eigen::Index> order(static_cast<std::size_t>(m));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index a, Eigen::Index b) { return d_in(a) < d_in(b); });
  Eigen::VectorXd d(m), z(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    d(i) = d_in(order[static_cast<std::size_t>(i)]);
    z(i) = z_in(order[static_cast<std::size_t>(i)]);
  }
  // z of unit norm, rho scaled to keep rho z z^T.
  const double z_norm = z.norm();
  const double r = rho * z_norm * z_norm;
  if (z_norm > 0.0) z /= z_norm;
  const double eps = std::numeric_limits<double>::epsilon();
  const double tol = 8.0 * eps * std::max(d.cwiseAbs().maxCoeff(), r);

  // Deflation: a negligible component, or a diagonal entry nearly equal to the last kept one
  // (a rotation moves its component onto that one).
  std::vector<bool> kept(static_cast<std::size_t>(m), false);
  std::vector<Givens> rotations;
  Eigen::Index last = -1;
  for (Eigen::Index i = 0; i < m; ++i) {
    if (r * std::abs(z(i)) <= tol) continue;
    if (last >= 0) {
      const double t = std::hypot(z(last), z(i));
      const double c = z(i) / t, s = z(last) / t;
      if (std::abs(c * s * (d(last) - d(i))) <= tol) {
        const double dp = c * c * d(last) + s * s * d(i);
        d(i) = s * s * d(last) + c * c * d(i);
        d(last) = dp;
        z(i) = t;
        z(last) = 0.0;
        kept[static_cast<std::size_t>(last)] = false;
        rotations.push_back({last, i, c, s});
      }
    }
    kept[static_cast<std::size_t>(i)] = true;
    last = i;
  }
  std::vector<Eigen::Index> index;  // the kept rows, d increasing
  for (Eigen::Index i = 0; i < m; ++i)
    if (kept[static_cast<std::size_t>(i)]) index.push_back(i);
  std::sort(index.begin(), index.end(),
            [&](Eigen::Index a, Eigen::Index b) { return d(a) < d(b); });
  const std::size_t k = index.size();
  std::vector<double> dk(k), zk(k);
  for (std::size_t j = 0; j < k; ++j) {
    dk[j] = d(index[j]);
    zk[j] = z(index[j]);
  }

  Eigen::VectorXd values = d;  // deflated rows keep their (rotated) diagonal entry
  Eigen::MatrixXd y = Eigen::MatrixXd::Identity(m, m);
  if (k > 0) {
    std::vector<std::size_t> origin(k);
    std::vector<double> tau(k);
    for (std::size_t i = 0; i < k; ++i) SolveSecular(dk, zk, r, i, &origin[i], &tau[i]);
    // mu_i - d_j, accurately: tau_i + (d[origin_i] - d_j).
    const auto mu_minus = [&](std::size_t i, std::size_t j) {
      return tau[i] + (dk[origin[i]] - dk[j]);
    };
    // Gu-Eisenstat: the z for which the computed eigenvalues are exact.
    std::vector<double> zhat(k);
    for (std::size_t j = 0; j < k; ++j) {
      double w = mu_minus(j, j) / r;
      for (std::size_t i = 0; i < k; ++i)
        if (i != j) w *= mu_minus(i, j) / (dk[i] - dk[j]);
      zhat[j] = std::copysign(std::sqrt(std::max(w, 0.0)), zk[j]);
    }
    for (std::size_t i = 0; i < k; ++i) {
      const Eigen::Index col = index[i];
      y.col(col).setZero();
      for (std::size_t j = 0; j < k; ++j) y(index[j], col) = zhat[j] / -mu_minus(i, j);
      y.col(col).normalize();
      values(col) = dk[origin[i]] + tau[i];
    }
  }
  // Undo the rotations (last first), then the sort.
  for (auto g = rotations.rbegin(); g != rotations.rend(); ++g) {
    const Eigen::RowVectorXd yp = y.row(g->p), yq = y.row(g->q);
    y.row(g->p) = g->c * yp + g->s * yq;
    y.row(g->q) = -g->s * yp + g->c * yq;
  }
  std::vector<Eigen::Index> by_value(static_cast<std::size_t>(m));
  std::iota(by_value.begin(), by_value.end(), Eigen::Index{0});
  std::stable_sort(by_value.begin(), by_value.end(),
                   [&](Eigen::Index a, Eigen::Index b) { return values(a) > values(b); });
  RankOneEigen out;
  out.values.resize(m);
  out.vectors.resize(m, m);
  for (Eigen::Index c = 0; c < m; ++c) {
    const Eigen::Index from = by_value[static_cast<std::size_t>(c)];
    out.values(c) = values(from);
    for (Eigen::Index i = 0; i < m; ++i)
      out.vectors(order[static_cast<std::size_t>(i)], c) = y(i, from);
  }
  return out;
}

}  // namespace mapless::appearance

#pragma once
/// \file
/// The coefficient rows of the smoothness priors (control_rows_cost.h, thrust_acceleration_cost.h):
/// exact integrals of a squared derivative over one segment, and the jumps of the lower derivatives
/// at a breakpoint (docs/estimator.md, "The smoothness prior, exactly").

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "cheval/cheb/chebyshev.h"
#include "cheval/cheb/quadrature.h"

namespace cheval::estim::internal {

/// Rows sqrt(w_q L/2) x^(m)(t_q) over the N + 1 node values of a quantity x on segment `interval`
/// (point order k = 0..N) at `points` Gauss–Legendre points (t_q, w_q) (0: N − m + 1): with the
/// exact rule their squared sum |C X|² is ∫ |x^(m)|² dt over the segment, exactly (x^(m) is a
/// polynomial of degree N − m). `D`: the differentiation matrix on the unit interval.
inline Eigen::MatrixXd SmoothnessRows(const cheb::ChebyshevBasis& basis, const Eigen::MatrixXd& D,
                                      const cheb::Interval& interval, int order, int points = 0) {
  const int N = static_cast<int>(D.rows()) - 1;
  Eigen::MatrixXd Dm = Eigen::MatrixXd::Identity(N + 1, N + 1);
  for (int i = 0; i < order; ++i) Dm = D * Dm;
  const int nq = points > 0 ? points : N - order + 1;
  const cheb::QuadratureRule rule = cheb::GaussLegendre(nq);
  Eigen::RowVectorXd row(N + 1);
  const double length = interval.b - interval.a;
  const double scale = std::pow(interval.DerivativeScale(), order);
  Eigen::MatrixXd coefficients(nq, N + 1);
  for (int q = 0; q < nq; ++q) {
    basis.InterpolationRow(rule.nodes[q], row);
    coefficients.row(q) = std::sqrt(rule.weights[q] * length / 2) * scale * (row * Dm);
  }
  return coefficients;
}

/// The jumps x^(i)(t_b⁺) − x^(i)(t_b⁻), i = 1..m − 1, at the breakpoint t_b between segments `a` and
/// `b`, each divided by σ_i = σ h^(m−i−1/2) with h the shortest node spacing of the two (the prior's
/// change of x^(i) over one node step): m − 1 rows over the 2N + 1 node values of the two segments in
/// time order (segment a's start .. segment b's end).
inline Eigen::MatrixXd SmoothnessJumpRows(const cheb::ChebyshevBasis& basis, const Eigen::MatrixXd& D,
                                          const cheb::Interval& a, const cheb::Interval& b, int order, double sigma) {
  const int N = static_cast<int>(D.rows()) - 1;
  const double h_unit = 1.0 - basis.points()[1];
  const double scale_a = a.DerivativeScale(), scale_b = b.DerivativeScale();
  const double h = std::min(h_unit / scale_a, h_unit / scale_b);
  Eigen::MatrixXd coefficients = Eigen::MatrixXd::Zero(order - 1, 2 * N + 1);
  Eigen::MatrixXd Di = Eigen::MatrixXd::Identity(N + 1, N + 1);
  for (int i = 1; i < order; ++i) {
    Di = D * Di;
    const double sigma_i = sigma * std::pow(h, order - i - 0.5);
    // Segment a ends at its point k = 0 (column N); segment b starts at its point k = N (column N).
    for (int k = 0; k <= N; ++k) {
      coefficients(i - 1, N - k) += std::pow(scale_a, i) * Di(0, k) / sigma_i;
      coefficients(i - 1, 2 * N - k) -= std::pow(scale_b, i) * Di(N, k) / sigma_i;
    }
  }
  return coefficients;
}

}  // namespace cheval::estim::internal

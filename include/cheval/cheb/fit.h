#pragma once
/// \file
/// Weighted least-squares fitting of vector samples by a Chebyshev polynomial, in O(m·N) without
/// forming the m x (N + 1) design matrix (CHEBYSHEV.md, "Least-squares fit of noisy samples").

#include <Eigen/Core>

#include "cheval/cheb/chebyshev.h"

namespace cheval::cheb {

/// A polynomial curve of degree N on an interval, R -> R^d, held as its Chebyshev coefficients.
struct ChebyshevSeries {
  Interval interval;
  /// (N + 1) x d: row k multiplies T_k(x), x = interval.ToUnit(t).
  Eigen::MatrixXd coefficients;

  int degree() const { return static_cast<int>(coefficients.rows()) - 1; }
  int dimension() const { return static_cast<int>(coefficients.cols()); }
  /// Value at time t (Clenshaw).
  Eigen::RowVectorXd Value(double t) const;
  /// d/dt at time t.
  Eigen::RowVectorXd Derivative(double t) const;
  /// The values at the N + 1 Chebyshev points of the interval (descending in t).
  Eigen::MatrixXd ValuesAtPoints() const;
};

/// Fits samples z_i ≈ p(t_i) in the least-squares sense with weights ω_i (nullptr = all 1):
/// minimises Σ ω_i |z_i - p(t_i)|² over polynomials p of degree N on `interval`.
///
/// In the coefficient basis the normal matrix is Toeplitz-plus-Hankel,
/// G_ij = (S_{i+j} + S_{|i-j|}) / 2 with S_n = Σ ω_i T_n(x_i), so building it and the right-hand
/// side costs O(m·N) and the solve O(N³). Normal equations square the condition number: this is
/// accurate while N²/m stays small (≲ 8 for equispaced samples), which the windowed fits ensure.
///
/// `t` (m) are seconds relative to any local origin, inside `interval`; `z` is m x d with d <= 4.
/// Throws ComputeError when fewer than N + 1 samples are given or the system is singular (the
/// LDLᵀ pivots span more than 1e13). If `gram_condition` is given it receives max/min of those
/// pivots, an estimate of the normal matrix's condition number (the square of the samples').
/// If `variance_factors` is given it receives diag(G⁻¹): with unit weights and white noise of
/// standard deviation σ on the samples, coefficient k has standard deviation σ·sqrt(factor_k).
ChebyshevSeries FitLeastSquares(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                                int degree, const Interval& interval, const Eigen::VectorXd* weights = nullptr,
                                double* gram_condition = nullptr, Eigen::VectorXd* variance_factors = nullptr);

}  // namespace cheval::cheb

#pragma once
/// \file
/// Weighted least-squares fitting of vector samples by a Chebyshev polynomial, in O(m·N) without
/// forming the m x (N + 1) design matrix (docs/velocity.md, "Formulas").

#include <utility>
#include <vector>

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

/// The normal equations of a weighted least-squares Chebyshev fit up to degree `top`: the fit of
/// any lower degree N uses their leading (N + 1) x (N + 1) block and first N + 1 rows, so one
/// O(m·top) pass over the samples serves every candidate degree.
///
/// In the coefficient basis the normal matrix is Toeplitz-plus-Hankel,
/// G_ij = (S_{i+j} + S_{|i-j|}) / 2 with S_n = Σ ω_i T_n(x_i), so building it and the right-hand
/// side costs O(m·N) and a solve O(N³). Normal equations square the condition number: this is
/// accurate while N²/m stays small (≲ 8 for equispaced samples), which the windowed fits ensure.
struct NormalEquations {
  Interval interval;
  Eigen::MatrixXd gram;  ///< (top + 1) x (top + 1)
  Eigen::MatrixXd rhs;   ///< (top + 1) x d: Σ ω_i T_k(x_i) z_i
  Eigen::Index samples = 0;
  int top_degree() const { return static_cast<int>(gram.rows()) - 1; }
};

/// Builds the normal equations of samples z_i at t_i (seconds relative to any local origin,
/// inside `interval`; z is m x d with d <= 4) with weights ω_i (nullptr = all 1), up to `top`.
/// Throws ComputeError when fewer than top + 1 samples are given.
NormalEquations BuildNormalEquations(const Eigen::Ref<const Eigen::VectorXd>& t,
                                     const Eigen::Ref<const Eigen::MatrixXd>& z, int top, const Interval& interval,
                                     const Eigen::VectorXd* weights = nullptr);

/// As BuildNormalEquations without the sample-count check: for sums of partial systems (e.g. the
/// folds of a cross-validation), where each part alone may be singular.
NormalEquations BuildNormalEquationsUnchecked(const Eigen::Ref<const Eigen::VectorXd>& t,
                                              const Eigen::Ref<const Eigen::MatrixXd>& z, int top,
                                              const Interval& interval, const Eigen::VectorXd* weights = nullptr);

/// Normal equations kept by the 2·top + 1 sums S_n their matrix is made of, in place of its
/// (top + 1)² entries: for systems held many at a time (the folds of a cross-validation, 1.3 MB
/// each at degree 400). `Gram()` builds the matrix exactly as BuildNormalEquations does.
struct NormalMoments {
  Interval interval;
  Eigen::VectorXd sums;  ///< S_0 .. S_{2·top}, S_n = Σ ω_i T_n(x_i)
  Eigen::MatrixXd rhs;   ///< (top + 1) x d: Σ ω_i T_k(x_i) z_i
  Eigen::Index samples = 0;
  int top_degree() const { return static_cast<int>(rhs.rows()) - 1; }
  /// G_ij = (S_{i+j} + S_{|i-j|}) / 2, (top + 1) x (top + 1).
  Eigen::MatrixXd Gram() const;
  NormalEquations Equations() const& { return NormalEquations{interval, Gram(), rhs, samples}; }
  /// As above, taking `rhs` instead of copying it.
  NormalEquations Equations() && { return NormalEquations{interval, Gram(), std::move(rhs), samples}; }
};

/// BuildNormalEquationsUnchecked's system by its sums.
NormalMoments BuildNormalMomentsUnchecked(const Eigen::Ref<const Eigen::VectorXd>& t,
                                          const Eigen::Ref<const Eigen::MatrixXd>& z, int top, const Interval& interval,
                                          const Eigen::VectorXd* weights = nullptr);

/// One Cholesky factorisation G = L·Lᵀ of normal equations serves the fit of every degree up to
/// its own: without pivoting, the factor of a leading block of G is the leading block of L. So a
/// degree search (cross-validation, the per-coordinate degrees of a window) costs one O(N³)
/// factorisation and O(N²) per candidate instead of O(N³) per candidate.
class NestedCholesky {
 public:
  /// Factorises the leading (degree + 1) x (degree + 1) block of `normal.gram`. Throws
  /// ComputeError when that block is singular (Cholesky pivots L_kk² spanning more than 1e13):
  /// the samples do not determine a polynomial of that degree.
  NestedCholesky(const NormalEquations& normal, int degree);

  int degree() const { return static_cast<int>(factor_.rows()) - 1; }
  /// max/min of the pivots L_kk² up to `degree`: a lower bound of the condition number of that
  /// block of G (the square of the samples' condition number).
  double Condition(int degree) const;
  /// Coefficients ((degree + 1) x d) of the degree-`degree` fit to right-hand sides whose first
  /// degree + 1 rows are used (e.g. NormalEquations::rhs).
  Eigen::MatrixXd Solve(int degree, const Eigen::Ref<const Eigen::MatrixXd>& rhs) const;
  /// L⁻¹·rhs over the leading degree + 1 rows of `rhs` ((degree + 1) x d): with G = L·Lᵀ,
  /// aᵀG⁻¹b = (L⁻¹a)ᵀ(L⁻¹b) for the block of that degree, and L being lower triangular, the
  /// leading rows of the result are those of every lower degree (one solve serves them all).
  Eigen::MatrixXd Whiten(int degree, const Eigen::Ref<const Eigen::MatrixXd>& rhs) const;
  /// diag(G⁻¹) of the degree-`degree` block: with unit weights and white noise of standard
  /// deviation σ, coefficient k of that fit has standard deviation σ·sqrt(factor_k).
  Eigen::VectorXd VarianceFactors(int degree) const { return VarianceFactors(degree, 0); }
  /// The same for coefficients first..degree only (degree − first + 1 values): column k of L⁻¹
  /// is zero above row k, so only the trailing block of L is inverted.
  Eigen::VectorXd VarianceFactors(int degree, int first) const;
  /// Held-out squared errors Σz² − 2cᵀb + cᵀGc (degrees.size() x d) of the fit of each degree of
  /// `degrees` (ascending, each at most degree()) to the right-hand sides `train_rhs` of the
  /// factorised system, on held-out samples given by their normal equations `held_out` (built up
  /// to at least the largest degree) and Σz² per coordinate `squares`: a cross-validation's score
  /// of every candidate degree in O(N²) each (the forward substitution is shared, L being lower
  /// triangular).
  Eigen::MatrixXd HeldOutErrors(const Eigen::Ref<const Eigen::MatrixXd>& train_rhs, const NormalEquations& held_out,
                                const Eigen::RowVectorXd& squares, const std::vector<int>& degrees) const;

 private:
  Eigen::MatrixXd factor_;  // lower triangular L
};

/// Solves the degree-N fit from normal equations built up to at least N (NestedCholesky). Throws
/// ComputeError when the system is singular. If `gram_condition` is given it receives
/// NestedCholesky::Condition; if `variance_factors` is given, NestedCholesky::VarianceFactors.
ChebyshevSeries SolveNormalEquations(const NormalEquations& normal, int degree, double* gram_condition = nullptr,
                                     Eigen::VectorXd* variance_factors = nullptr);

/// Fits samples z_i ≈ p(t_i) in the least-squares sense with weights ω_i (nullptr = all 1):
/// minimises Σ ω_i |z_i - p(t_i)|² over polynomials p of degree N on `interval`
/// (BuildNormalEquations + SolveNormalEquations).
ChebyshevSeries FitLeastSquares(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                                int degree, const Interval& interval, const Eigen::VectorXd* weights = nullptr,
                                double* gram_condition = nullptr, Eigen::VectorXd* variance_factors = nullptr);

/// Values of the series with coefficients ((N + 1) x d) at every x (unit interval): m x d, by
/// Clenshaw's recurrence over all points at once.
Eigen::MatrixXd EvaluateSeries(const Eigen::Ref<const Eigen::MatrixXd>& coefficients,
                               const Eigen::Ref<const Eigen::VectorXd>& x);

}  // namespace cheval::cheb

#pragma once
/// \file
/// Chebyshev–Gauss–Lobatto numerics on [-1, 1] (Trefethen, *Spectral Methods in MATLAB*, `cheb.m`;
/// Berrut & Trefethen, *Barycentric Lagrange Interpolation*, SIAM Review 2004).
///
/// Convention: **degree N means N + 1 points** x_j = cos(jπ/N), j = 0..N, in DESCENDING order
/// (x_0 = 1, x_N = -1), as in `cheb.m` and both papers. A polynomial of degree N is represented by
/// its N + 1 values f_j = p(x_j) ("values") or by its Chebyshev coefficients p = Σ_k c_k T_k
/// ("coefficients"); ValuesToCoefficients / CoefficientsToValues convert between the two exactly
/// (a DCT-I through an FFT). An interval [a, b] maps to [-1, 1] by x = (2t - a - b)/(b - a), so every
/// d/dt carries the factor 2/(b - a) (Interval::DerivativeScale).

#include <Eigen/Core>

namespace cheval::cheb {

/// An interval [a, b] of time (seconds, relative to a local origin — never epoch seconds).
struct Interval {
  double a = -1.0;
  double b = 1.0;

  /// x in [-1, 1] of t in [a, b].
  double ToUnit(double t) const { return (2.0 * t - a - b) / (b - a); }
  /// t in [a, b] of x in [-1, 1].
  double FromUnit(double x) const { return 0.5 * (a + b) + 0.5 * (b - a) * x; }
  /// dx/dt = 2 / (b - a): multiply a derivative in x by this to get one in t.
  double DerivativeScale() const { return 2.0 / (b - a); }
};

/// The N + 1 Chebyshev–Gauss–Lobatto points cos(jπ/N), j = 0..N, descending. Computed as
/// sin(π(N - 2j)/(2N)) so that they are exactly symmetric (x_{N-j} = -x_j, x_{N/2} = 0).
/// Precondition: degree >= 1.
Eigen::VectorXd ChebyshevPoints(int degree);

/// The points mapped to `interval` (descending: the first is b, the last a).
Eigen::VectorXd ChebyshevPoints(int degree, const Interval& interval);

/// Barycentric weights of the second-kind formula for these points: (-1)^j, halved at j = 0, N.
Eigen::VectorXd BarycentricWeights(int degree);

/// The points and barycentric weights of one degree, for repeated interpolation and
/// differentiation rows (the measurement rows of a fit or an estimator).
class ChebyshevBasis {
 public:
  /// Precondition: degree >= 1.
  explicit ChebyshevBasis(int degree);

  int degree() const { return degree_; }
  /// The N + 1 points, descending.
  const Eigen::VectorXd& points() const { return points_; }
  /// The barycentric weights.
  const Eigen::VectorXd& weights() const { return weights_; }

  /// The row w(x) with p(x) = w(x) · f for the values f at the points (barycentric formula of the
  /// second kind). x in [-1, 1] (outside it, extrapolation is computed but ill-conditioned). A node
  /// hit (x == x_j exactly) gives the unit row e_j, never 0/0 (GTSAM's tolerance-in-index test
  /// misses exact nodes for N >= 256). `row` must have degree + 1 entries.
  void InterpolationRow(double x, Eigen::Ref<Eigen::RowVectorXd> row) const;

  /// The row w'(x) with p'(x) = w'(x) · f (derivative in x). At a node it is that row of
  /// DifferentiationMatrix. `row` must have degree + 1 entries.
  void DerivativeRow(double x, Eigen::Ref<Eigen::RowVectorXd> row) const;

  /// Index of the point equal to x (exact comparison), or -1.
  int NodeIndex(double x) const;

 private:
  int degree_;
  Eigen::VectorXd points_;
  Eigen::VectorXd weights_;
};

/// The (N + 1) x (N + 1) differentiation matrix D in x: (D f)_i = p'(x_i). Off the diagonal
/// D_ij = (c_i / c_j)(-1)^(i+j) / (x_i - x_j) with c_0 = c_N = 2, else 1; each diagonal entry is
/// minus the sum of the rest of its row (the negative-sum trick, Baltensperger & Trummer 2003), so
/// D·1 = 0 to rounding (|D·1| ~ 1e-10 at N = 1024 instead of 1e-5 with the textbook diagonal).
Eigen::MatrixXd DifferentiationMatrix(int degree);

/// Chebyshev coefficients (rows k = 0..N) of the polynomials whose values at the N + 1 points are
/// the columns of `values` ((N + 1) x d). DCT-I via an FFT of length 2N: O(N log N) per column.
Eigen::MatrixXd ValuesToCoefficients(const Eigen::Ref<const Eigen::MatrixXd>& values);

/// Values at the N + 1 points of the polynomials with the given coefficients ((N + 1) x d). Exact
/// inverse of ValuesToCoefficients.
Eigen::MatrixXd CoefficientsToValues(const Eigen::Ref<const Eigen::MatrixXd>& coefficients);

/// Σ_k c_k T_k(x) for each column of `coefficients` by Clenshaw's recurrence (stable, O(N)).
Eigen::RowVectorXd Clenshaw(const Eigen::Ref<const Eigen::MatrixXd>& coefficients, double x);

/// The same polynomials on another interval: the coefficients on `to` (rows k = 0..N, a column per
/// polynomial) of those whose coefficients on `from` are `coefficients`, exactly (their values at
/// the N + 1 Chebyshev points of `to`). Outside `from` the polynomials are extrapolated, and their
/// coefficients can grow by orders of magnitude over their values.
Eigen::MatrixXd Reexpand(const Eigen::Ref<const Eigen::MatrixXd>& coefficients, const Interval& from, const Interval& to);

/// Coefficients of the derivative d/dx of Σ c_k T_k (same number of rows; the last is 0), by the
/// recurrence c'_{k-1} = c'_{k+1} + 2k c_k (with c'_0 halved).
Eigen::MatrixXd DerivativeCoefficients(const Eigen::Ref<const Eigen::MatrixXd>& coefficients);

}  // namespace cheval::cheb

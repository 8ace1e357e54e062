#include "cheval/cheb/chebyshev.h"

#include <cassert>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <unsupported/Eigen/FFT>

namespace cheval::cheb {

Eigen::VectorXd ChebyshevPoints(int degree) {
  assert(degree >= 1);
  Eigen::VectorXd x(degree + 1);
  const double n = degree;
  for (int j = 0; j <= degree; ++j) x[j] = std::sin(std::numbers::pi * (n - 2.0 * j) / (2.0 * n));
  return x;
}

Eigen::VectorXd ChebyshevPoints(int degree, const Interval& interval) {
  Eigen::VectorXd t = ChebyshevPoints(degree);
  for (Eigen::Index j = 0; j < t.size(); ++j) t[j] = interval.FromUnit(t[j]);
  return t;
}

Eigen::VectorXd BarycentricWeights(int degree) {
  Eigen::VectorXd w(degree + 1);
  for (int j = 0; j <= degree; ++j) w[j] = (j % 2 == 0) ? 1.0 : -1.0;
  w[0] *= 0.5;
  w[degree] *= 0.5;
  return w;
}

namespace {

// One row of D (negative-sum diagonal), computed without forming the matrix.
void DifferentiationRow(const Eigen::VectorXd& x, int i, Eigen::Ref<Eigen::RowVectorXd> row) {
  const int n = static_cast<int>(x.size()) - 1;
  auto c = [n](int k) { return (k == 0 || k == n) ? 2.0 : 1.0; };
  double sum = 0.0;
  for (int j = 0; j <= n; ++j) {
    if (j == i) continue;
    const double sign = ((i + j) % 2 == 0) ? 1.0 : -1.0;
    row[j] = c(i) / c(j) * sign / (x[i] - x[j]);
    sum += row[j];
  }
  row[i] = -sum;
}

}  // namespace

ChebyshevBasis::ChebyshevBasis(int degree)
    : degree_(degree), points_(ChebyshevPoints(degree)), weights_(BarycentricWeights(degree)) {}

int ChebyshevBasis::NodeIndex(double x) const {
  // Exact comparison on purpose: an x that is not bitwise a node is handled accurately by the
  // barycentric formula however close it is (Higham 2004: the formula is forward stable).
  if (x > 1.0 || x < -1.0) return -1;
  for (Eigen::Index j = 0; j < points_.size(); ++j) {
    if (x == points_[j]) return static_cast<int>(j);
  }
  return -1;
}

void ChebyshevBasis::InterpolationRow(double x, Eigen::Ref<Eigen::RowVectorXd> row) const {
  assert(row.size() == degree_ + 1);
  const int hit = NodeIndex(x);
  if (hit >= 0) {
    row.setZero();
    row[hit] = 1.0;
    return;
  }
  double denominator = 0.0;
  for (int j = 0; j <= degree_; ++j) {
    row[j] = weights_[j] / (x - points_[j]);
    denominator += row[j];
  }
  row /= denominator;
}

void ChebyshevBasis::DerivativeRow(double x, Eigen::Ref<Eigen::RowVectorXd> row) const {
  assert(row.size() == degree_ + 1);
  const int hit = NodeIndex(x);
  if (hit >= 0) {
    DifferentiationRow(points_, hit, row);
    return;
  }
  // l_j(x) = (w_j/(x-x_j)) / s with s = Σ w_k/(x-x_k); l_j'(x) = l_j(x)·(q/s - 1/(x-x_j)) with
  // q = Σ w_k/(x-x_k)².
  double s = 0.0, q = 0.0;
  for (int j = 0; j <= degree_; ++j) {
    const double d = x - points_[j];
    row[j] = weights_[j] / d;
    s += row[j];
    q += row[j] / d;
  }
  for (int j = 0; j <= degree_; ++j) row[j] = row[j] / s * (q / s - 1.0 / (x - points_[j]));
}

Eigen::MatrixXd DifferentiationMatrix(int degree) {
  const Eigen::VectorXd x = ChebyshevPoints(degree);
  Eigen::MatrixXd D(degree + 1, degree + 1);
  Eigen::RowVectorXd row(degree + 1);
  for (int i = 0; i <= degree; ++i) {
    DifferentiationRow(x, i, row);
    D.row(i) = row;
  }
  return D;
}

namespace {

// DCT-I of each column: y_k = Σ_j'' v_j cos(π j k / N) (ends halved), through an FFT of the even
// extension [v_0 .. v_N, v_{N-1} .. v_1] of length 2N, whose transform is 2·y (real).
Eigen::MatrixXd DctI(const Eigen::Ref<const Eigen::MatrixXd>& v) {
  const Eigen::Index n = v.rows() - 1;
  Eigen::MatrixXd y(v.rows(), v.cols());
  if (n == 0) {
    y = v;
    return y;
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> extended(2 * n), spectrum;
  for (Eigen::Index col = 0; col < v.cols(); ++col) {
    for (Eigen::Index j = 0; j <= n; ++j) extended[j] = v(j, col);
    for (Eigen::Index j = 1; j < n; ++j) extended[2 * n - j] = v(j, col);
    fft.fwd(spectrum, extended);
    for (Eigen::Index k = 0; k <= n; ++k) y(k, col) = 0.5 * spectrum[k].real();
  }
  return y;
}

}  // namespace

Eigen::MatrixXd ValuesToCoefficients(const Eigen::Ref<const Eigen::MatrixXd>& values) {
  // f_j = Σ_k c_k cos(πjk/N) at x_j = cos(πj/N). Then c_k = (2/N)·DCT-I(f)_k, halved at k = 0, N.
  const Eigen::Index n = values.rows() - 1;
  if (n == 0) return values;
  Eigen::MatrixXd c = DctI(values) * (2.0 / static_cast<double>(n));
  c.row(0) *= 0.5;
  c.row(n) *= 0.5;
  return c;
}

Eigen::MatrixXd CoefficientsToValues(const Eigen::Ref<const Eigen::MatrixXd>& coefficients) {
  // f_j = Σ_k c_k cos(πjk/N) = DCT-I of c with the ends doubled (DCT-I halves them).
  const Eigen::Index n = coefficients.rows() - 1;
  if (n == 0) return coefficients;
  Eigen::MatrixXd c = coefficients;
  c.row(0) *= 2.0;
  c.row(n) *= 2.0;
  return DctI(c);
}

Eigen::RowVectorXd Clenshaw(const Eigen::Ref<const Eigen::MatrixXd>& coefficients, double x) {
  const Eigen::Index n = coefficients.rows() - 1;
  Eigen::RowVectorXd b1 = Eigen::RowVectorXd::Zero(coefficients.cols());
  Eigen::RowVectorXd b2 = b1;
  for (Eigen::Index k = n; k >= 1; --k) {
    Eigen::RowVectorXd b0 = 2.0 * x * b1 - b2 + coefficients.row(k);
    b2 = b1;
    b1 = b0;
  }
  return x * b1 - b2 + coefficients.row(0);
}

Eigen::MatrixXd Reexpand(const Eigen::Ref<const Eigen::MatrixXd>& coefficients, const Interval& from, const Interval& to) {
  const auto n = static_cast<int>(coefficients.rows()) - 1;
  if (n <= 0) return coefficients;
  const Eigen::VectorXd points = ChebyshevPoints(n, to);
  Eigen::MatrixXd values(n + 1, coefficients.cols());
  for (int k = 0; k <= n; ++k) values.row(k) = Clenshaw(coefficients, from.ToUnit(points[k]));
  return ValuesToCoefficients(values);
}

Eigen::MatrixXd DerivativeCoefficients(const Eigen::Ref<const Eigen::MatrixXd>& coefficients) {
  const Eigen::Index n = coefficients.rows() - 1;
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(coefficients.rows(), coefficients.cols());
  if (n == 0) return d;
  // d_{k-1} = d_{k+1} + 2k c_k for k = n .. 1, with d_n = d_{n+1} = 0; then d_0 /= 2.
  for (Eigen::Index k = n; k >= 1; --k) {
    d.row(k - 1) = 2.0 * static_cast<double>(k) * coefficients.row(k);
    if (k + 1 <= n) d.row(k - 1) += d.row(k + 1);
  }
  d.row(0) *= 0.5;
  return d;
}

}  // namespace cheval::cheb

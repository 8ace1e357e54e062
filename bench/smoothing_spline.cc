#include "smoothing_spline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace cheval::bench {
namespace {

// One coordinate on fixed knots t. With h_i = t_{i+1} − t_i, Q (n × n−2) the second-difference
// operator and R (n−2 × n−2) the tridiagonal Gram matrix of the spline's second derivatives, the
// interior second derivatives γ solve (R + λ QᵀQ) γ = Qᵀ y and the fitted values are y − λ Q γ.
class Spline {
 public:
  explicit Spline(const std::vector<double>& t) : n_(t.size()), k_(n_ - 2), h_(n_ - 1) {
    for (std::size_t i = 0; i + 1 < n_; ++i) h_[i] = t[i + 1] - t[i];
  }

  struct Fit {
    double gcv;
    std::vector<double> values, gamma;  // gamma has n entries, natural ends 0
  };

  Fit Solve(const std::vector<double>& y, double lambda) const {
    // Pentadiagonal M = R + λ QᵀQ in three diagonals m0 (j,j), m1 (j,j+1), m2 (j,j+2).
    std::vector<double> m0(k_), m1(k_, 0.0), m2(k_, 0.0), rhs(k_);
    for (std::size_t j = 0; j < k_; ++j) {
      const double a = 1 / h_[j], b = -1 / h_[j] - 1 / h_[j + 1], c = 1 / h_[j + 1];  // column j of Q: rows j..j+2
      m0[j] = (h_[j] + h_[j + 1]) / 3 + lambda * (a * a + b * b + c * c);
      if (j + 1 < k_) {
        const double a1 = 1 / h_[j + 1], b1 = -1 / h_[j + 1] - 1 / h_[j + 2];  // column j+1: rows j+1..j+3
        m1[j] = h_[j + 1] / 6 + lambda * (b * a1 + c * b1);
      }
      if (j + 2 < k_) m2[j] = lambda * c * (1 / h_[j + 2]);
      rhs[j] = a * y[j] + b * y[j + 1] + c * y[j + 2];
    }
    // LDLᵀ with L unit lower, bandwidth 2: l1[j] = L(j+1, j), l2[j] = L(j+2, j).
    std::vector<double> d(k_), l1(k_, 0.0), l2(k_, 0.0);
    for (std::size_t j = 0; j < k_; ++j) {
      double dj = m0[j];
      if (j >= 1) dj -= l1[j - 1] * l1[j - 1] * d[j - 1];
      if (j >= 2) dj -= l2[j - 2] * l2[j - 2] * d[j - 2];
      d[j] = dj;
      if (j + 1 < k_) {
        double v = m1[j];
        if (j >= 1) v -= l2[j - 1] * l1[j - 1] * d[j - 1];
        l1[j] = v / dj;
      }
      if (j + 2 < k_) l2[j] = m2[j] / dj;
    }
    std::vector<double> z(rhs);
    for (std::size_t j = 0; j < k_; ++j) {
      if (j >= 1) z[j] -= l1[j - 1] * z[j - 1];
      if (j >= 2) z[j] -= l2[j - 2] * z[j - 2];
    }
    for (std::size_t j = 0; j < k_; ++j) z[j] /= d[j];
    for (std::size_t j = k_; j-- > 0;) {
      if (j + 1 < k_) z[j] -= l1[j] * z[j + 1];
      if (j + 2 < k_) z[j] -= l2[j] * z[j + 2];
    }
    Fit fit;
    fit.gamma.assign(n_, 0.0);
    for (std::size_t j = 0; j < k_; ++j) fit.gamma[j + 1] = z[j];
    fit.values = y;
    double rss = 0;
    for (std::size_t j = 0; j < k_; ++j) {  // values −= λ Q γ
      fit.values[j] -= lambda * z[j] / h_[j];
      fit.values[j + 1] -= lambda * z[j] * (-1 / h_[j] - 1 / h_[j + 1]);
      fit.values[j + 2] -= lambda * z[j] / h_[j + 1];
    }
    for (std::size_t i = 0; i < n_; ++i) rss += (y[i] - fit.values[i]) * (y[i] - fit.values[i]);
    // tr A = 2 + tr(M⁻¹R): only the diagonal and first off-diagonal of S = M⁻¹ are needed, from
    // S = D⁻¹L⁻¹ + (I − Lᵀ) S, backwards.
    double trace = 2;
    double s00_next = 0, s01_next = 0, s11_next = 0;  // S(j+1,j+1), S(j+1,j+2), S(j+2,j+2)
    for (std::size_t j = k_; j-- > 0;) {
      const double s_j_j1 = -l1[j] * s00_next - l2[j] * s01_next;   // S(j, j+1)
      const double s_j_j2 = -l1[j] * s01_next - l2[j] * s11_next;   // S(j, j+2)
      const double s_jj = 1 / d[j] - l1[j] * s_j_j1 - l2[j] * s_j_j2;
      trace += s_jj * (h_[j] + h_[j + 1]) / 3;
      if (j + 1 < k_) trace += 2 * s_j_j1 * h_[j + 1] / 6;
      s11_next = s00_next;
      s01_next = s_j_j1;
      s00_next = s_jj;
    }
    const double n = static_cast<double>(n_);
    fit.gcv = n * rss / std::max((n - trace) * (n - trace), std::numeric_limits<double>::min());
    return fit;
  }

  std::vector<double> Derivative(const Fit& fit) const {
    std::vector<double> v(n_);
    const auto& f = fit.values;
    const auto& g = fit.gamma;
    for (std::size_t i = 0; i + 1 < n_; ++i) v[i] = (f[i + 1] - f[i]) / h_[i] - h_[i] * (2 * g[i] + g[i + 1]) / 6;
    const std::size_t i = n_ - 2;
    v[n_ - 1] = (f[i + 1] - f[i]) / h_[i] + h_[i] * (g[i] + 2 * g[i + 1]) / 6;
    return v;
  }

 private:
  std::size_t n_, k_;
  std::vector<double> h_;
};

}  // namespace

Eigen::Matrix3Xd SmoothingSplineVelocity(std::span<const int64_t> stamps_ns, const Eigen::Matrix3Xd& positions) {
  const std::size_t n = stamps_ns.size();
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = 1e-9 * static_cast<double>(stamps_ns[i] - stamps_ns[0]);
  const Spline spline(t);
  const double mean_h = t.back() / static_cast<double>(n - 1);
  Eigen::Matrix3Xd velocity(3, n);
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> y(n);
    for (std::size_t i = 0; i < n; ++i) y[i] = positions(axis, static_cast<Eigen::Index>(i));
    // λ scales like h³ (R ~ h, QᵀQ ~ 1/h²): a grid of log λ over 16 decades around h³, then golden
    // section around the best grid point.
    auto gcv = [&](double log_lambda) { return spline.Solve(y, std::pow(10.0, log_lambda)).gcv; };
    const double centre = 3 * std::log10(mean_h);
    double best = centre - 8, best_gcv = gcv(best);
    for (double x = centre - 8; x <= centre + 8 + 1e-9; x += 0.25) {
      const double g = gcv(x);
      if (g < best_gcv) best = x, best_gcv = g;
    }
    double lo = best - 0.25, hi = best + 0.25;
    const double r = (std::sqrt(5.0) - 1) / 2;
    double a = hi - r * (hi - lo), b = lo + r * (hi - lo), ga = gcv(a), gb = gcv(b);
    for (int it = 0; it < 30; ++it) {
      if (ga < gb) hi = b, b = a, gb = ga, a = hi - r * (hi - lo), ga = gcv(a);
      else lo = a, a = b, ga = gb, b = lo + r * (hi - lo), gb = gcv(b);
    }
    const std::vector<double> v = spline.Derivative(spline.Solve(y, std::pow(10.0, (lo + hi) / 2)));
    for (std::size_t i = 0; i < n; ++i) velocity(axis, static_cast<Eigen::Index>(i)) = v[i];
  }
  return velocity;
}

}  // namespace cheval::bench

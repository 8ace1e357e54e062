#pragma once
/// \file
/// Truncated Taylor arithmetic: the simulator's exact derivatives (docs/sim.md, "Frames and
/// exactness"). Internal to src/sim.
///
/// A Jet holds the Taylor coefficients of a function around a time t₀, f(t₀ + τ) = Σ c[k] τ^k for
/// k < kTerms: c[0] is the value, c[1] the first derivative, c[2] half the second, c[3] a sixth of
/// the third. Contract: every operation below returns the coefficients of the exact result's series
/// truncated to kTerms terms, computed from the operands' kTerms coefficients (so a closed form built
/// from Jet::Variable(t) carries its derivatives up to order kTerms − 1 exactly, up to rounding:
/// forward-mode differentiation of any order, without finite differences). Preconditions: b.c[0] ≠ 0
/// for a / b; u.c[0] > 0 for sqrt(u). Derivative() is the one operation that loses information: the
/// top coefficient of its result is unknown and set to 0, so its result is exact only up to order
/// kTerms − 2.

#include <array>
#include <cmath>

namespace cheval::sim::internal {

/// Number of Taylor coefficients: value and three derivatives. Four suffice: the drone's attitude
/// needs the derivative of its acceleration, p'''.
inline constexpr int kTerms = 4;

struct Jet {
  std::array<double, kTerms> c{};

  Jet() = default;
  /// A constant: c = (value, 0, 0, 0).
  Jet(double value) { c[0] = value; }  // NOLINT(google-explicit-constructor): constants mix freely
  /// The independent variable at t: c = (t, 1, 0, 0).
  static Jet Variable(double t) {
    Jet x(t);
    x.c[1] = 1.0;
    return x;
  }

  friend Jet operator+(const Jet& a, const Jet& b) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) r.c[k] = a.c[k] + b.c[k];
    return r;
  }
  friend Jet operator-(const Jet& a, const Jet& b) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) r.c[k] = a.c[k] - b.c[k];
    return r;
  }
  friend Jet operator-(const Jet& a) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) r.c[k] = -a.c[k];
    return r;
  }
  /// Cauchy product: r_k = Σ_{j ≤ k} a_j b_{k−j}.
  friend Jet operator*(const Jet& a, const Jet& b) {
    Jet r;
    for (int k = 0; k < kTerms; ++k) {
      for (int j = 0; j <= k; ++j) r.c[k] += a.c[j] * b.c[k - j];
    }
    return r;
  }
  /// q with q·b = a: q_k = (a_k − Σ_{1 ≤ j ≤ k} b_j q_{k−j}) / b_0.
  friend Jet operator/(const Jet& a, const Jet& b) {
    Jet q;
    for (int k = 0; k < kTerms; ++k) {
      double s = a.c[k];
      for (int j = 1; j <= k; ++j) s -= b.c[j] * q.c[k - j];
      q.c[k] = s / b.c[0];
    }
    return q;
  }
  friend Jet sin(const Jet& u) { return SinCos(u)[0]; }
  friend Jet cos(const Jet& u) { return SinCos(u)[1]; }
  /// (sin u, cos u) together, from s' = c u', c' = −s u' coefficient by coefficient:
  /// k s_k = Σ_{1 ≤ j ≤ k} j u_j c_{k−j}, k c_k = −Σ_{1 ≤ j ≤ k} j u_j s_{k−j}.
  static std::array<Jet, 2> SinCos(const Jet& u) {
    Jet s, c;
    s.c[0] = std::sin(u.c[0]);
    c.c[0] = std::cos(u.c[0]);
    for (int k = 1; k < kTerms; ++k) {
      double ds = 0.0, dc = 0.0;
      for (int j = 1; j <= k; ++j) {
        ds += j * u.c[j] * c.c[k - j];
        dc += j * u.c[j] * s.c[k - j];
      }
      s.c[k] = ds / k;
      c.c[k] = -dc / k;
    }
    return {s, c};
  }
  /// r with r·r = u: r_k = (u_k − Σ_{1 ≤ j < k} r_j r_{k−j}) / (2 r_0).
  friend Jet sqrt(const Jet& u) {
    Jet r;
    r.c[0] = std::sqrt(u.c[0]);
    for (int k = 1; k < kTerms; ++k) {
      double s = u.c[k];
      for (int j = 1; j < k; ++j) s -= r.c[j] * r.c[k - j];
      r.c[k] = s / (2.0 * r.c[0]);
    }
    return r;
  }
  /// d/dτ of the series: d_k = (k + 1) u_{k+1}; the top coefficient is unknown and set to 0.
  friend Jet Derivative(const Jet& u) {
    Jet d;
    for (int k = 0; k + 1 < kTerms; ++k) d.c[k] = (k + 1) * u.c[k + 1];
    return d;
  }
  /// The series with value `value` at τ = 0 whose derivative is `d`: r_k = d_{k−1} / k (exact; uses d
  /// up to order kTerms − 2, so it undoes Derivative()).
  friend Jet Antiderivative(double value, const Jet& d) {
    Jet r(value);
    for (int k = 1; k < kTerms; ++k) r.c[k] = d.c[k - 1] / k;
    return r;
  }
  /// atan u = atan u₀ + ∫ u' / (1 + u²).
  friend Jet atan(const Jet& u) { return Antiderivative(std::atan(u.c[0]), Derivative(u) / (1.0 + u * u)); }
};

}  // namespace cheval::sim::internal

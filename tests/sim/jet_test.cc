// The Taylor jet of the simulator (src/sim/internal/jet.h): the coefficients of known functions are
// their derivatives divided by k!, exactly where the arithmetic is exact and to a few ulps otherwise.
#include "internal/jet.h"

#include <gtest/gtest.h>

#include <cmath>

namespace cheval::sim::internal {
namespace {

// Relative tolerance of a coefficient computed through a few libm calls and products: a few ulps.
constexpr double kUlps = 8 * 2.220446049250313e-16;

// `scale`: the size of the terms that make up a coefficient, when it is larger than the result (cancellation).
void ExpectCoefficients(const Jet& jet, const std::array<double, kTerms>& expected, double scale = 1.0) {
  for (int k = 0; k < kTerms; ++k) {
    EXPECT_NEAR(jet.c[k], expected[k], kUlps * std::max(scale, std::abs(expected[k]))) << "coefficient " << k;
  }
}

TEST(Jet, PolynomialsAreExact) {
  // f = t³ − 2t² + 5 at t = 0.5 (binary-exact): f = 4.625, f' = 3t² − 4t = −1.25, f''/2 = 3t − 2 = −0.5,
  // f'''/6 = 1. Every step is exact in double, so the coefficients are equal, not near.
  const Jet t = Jet::Variable(0.5);
  const Jet f = t * t * t - 2.0 * t * t + 5.0;
  EXPECT_EQ(f.c, (std::array<double, kTerms>{4.625, -1.25, -0.5, 1.0}));
  // Division by a polynomial: 1 / (1 + t) at t = 1 has coefficients (−1)^k / 2^(k+1), all exact.
  const Jet g = 1.0 / (1.0 + Jet::Variable(1.0));
  EXPECT_EQ(g.c, (std::array<double, kTerms>{0.5, -0.25, 0.125, -0.0625}));
  // sqrt(u) · sqrt(u) = u to all orders (u = 4 + 3τ + τ² has an exact root 2 at τ = 0).
  Jet u = Jet::Variable(0.0) * Jet::Variable(0.0) + 3.0 * Jet::Variable(0.0) + 4.0;
  const Jet r = sqrt(u);
  EXPECT_EQ(r.c[0], 2.0);
  EXPECT_EQ(r.c[1], 0.75);  // (√u)' = u' / (2√u) = 3/4
  ExpectCoefficients(r * r, u.c);
}

TEST(Jet, SinCosAtanMatchTheirDerivatives) {
  const double t0 = 0.7, w = 3.0, phi = 1.0;
  const Jet t = Jet::Variable(t0);
  const double x = w * t0 + phi;
  // sin(w t + φ): w cos x, −w² sin x / 2, −w³ cos x / 6.
  ExpectCoefficients(sin(w * t + phi),
                     {std::sin(x), w * std::cos(x), -w * w * std::sin(x) / 2, -w * w * w * std::cos(x) / 6});
  ExpectCoefficients(cos(w * t + phi),
                     {std::cos(x), -w * std::sin(x), -w * w * std::cos(x) / 2, w * w * w * std::sin(x) / 6});
  // atan t: 1/(1+t²), −t/(1+t²)², (3t² − 1)/(3(1+t²)³).
  const double d = 1.0 + t0 * t0;
  ExpectCoefficients(atan(t), {std::atan(t0), 1.0 / d, -t0 / (d * d), (3.0 * t0 * t0 - 1.0) / (3.0 * d * d * d)});
  // sin² + cos² = 1 to every order. Of u = 3t² + 1 at 0.7 the coefficients are (2.47, 4.2, 3, 0), so
  // the third coefficients of s² and c² are sums of terms up to u₁³ ≈ 74 that cancel.
  const auto [s, c] = Jet::SinCos(w * t * t + phi);
  ExpectCoefficients(s * s + c * c, {1.0, 0.0, 0.0, 0.0}, 74.0);
}

TEST(Jet, DerivativeShiftsAndAntiderivativeUndoesIt) {
  const Jet t = Jet::Variable(0.5);
  const Jet f = t * t * t - 2.0 * t * t + 5.0;  // coefficients (4.625, −1.25, −0.5, 1)
  const Jet d = Derivative(f);                  // f' = 3t² − 4t: (−1.25, −1, 3, 0 — the unknown top term)
  EXPECT_EQ(d.c, (std::array<double, kTerms>{-1.25, -1.0, 3.0, 0.0}));
  EXPECT_EQ(Antiderivative(f.c[0], d).c, f.c);
}

}  // namespace
}  // namespace cheval::sim::internal

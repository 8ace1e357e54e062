#include "cheval/cheb/chebyshev.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace cheval::cheb {
namespace {

TEST(ChebyshevPoints, DescendingSymmetricWithExactEnds) {
  for (int n : {1, 2, 7, 8, 64, 1024}) {
    const Eigen::VectorXd x = ChebyshevPoints(n);
    ASSERT_EQ(x.size(), n + 1);
    EXPECT_EQ(x[0], 1.0);
    EXPECT_EQ(x[n], -1.0);
    for (int j = 0; j <= n; ++j) {
      EXPECT_EQ(x[j], -x[n - j]);  // exact symmetry from the sine form
      if (j > 0) {
        EXPECT_LT(x[j], x[j - 1]);
      }
      EXPECT_NEAR(x[j], std::cos(j * M_PI / n), 1e-15);
    }
    if (n % 2 == 0) {
      EXPECT_EQ(x[n / 2], 0.0);
    }
  }
  const Eigen::VectorXd t = ChebyshevPoints(4, Interval{10.0, 12.0});
  EXPECT_EQ(t[0], 12.0);
  EXPECT_EQ(t[2], 11.0);
  EXPECT_EQ(t[4], 10.0);
}

TEST(DifferentiationMatrix, NegativeSumTrickAtDegree1024) {
  const Eigen::MatrixXd D = DifferentiationMatrix(1024);
  // docs/velocity.md "Formulas": textbook diagonal 1.2e-5, negative-sum trick ~4e-10 (entries reach ~7e5).
  EXPECT_LE((D * Eigen::VectorXd::Ones(1025)).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(DifferentiationMatrix, ExactOnPolynomialsUpToTheDegree) {
  const int n = 16;
  const Eigen::VectorXd x = ChebyshevPoints(n);
  const Eigen::MatrixXd D = DifferentiationMatrix(n);
  for (int k = 0; k <= n; ++k) {
    const Eigen::VectorXd f = x.array().pow(k);
    const Eigen::VectorXd expected = k == 0 ? Eigen::VectorXd::Zero(n + 1) : Eigen::VectorXd(k * x.array().pow(k - 1));
    // ||D|| ~ 2N²/3 ≈ 170 at N = 16, so rounding of order 170·eps·k is expected.
    EXPECT_LE((D * f - expected).cwiseAbs().maxCoeff(), 1e-12 * (k + 1)) << "k = " << k;
  }
}

TEST(Transform, RoundTripAndUnitCoefficients) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal;
  for (int n : {1, 2, 3, 16, 255, 256, 1000}) {
    Eigen::MatrixXd values(n + 1, 3);
    for (Eigen::Index i = 0; i < values.size(); ++i) values.data()[i] = normal(rng);
    const Eigen::MatrixXd back = CoefficientsToValues(ValuesToCoefficients(values));
    // An FFT round trip loses O(log N) ulps relative to the largest value (~4 for these normals).
    EXPECT_LE((back - values).cwiseAbs().maxCoeff(), 1e-14 * values.cwiseAbs().maxCoeff()) << "N = " << n;
  }
  // The values of T_k at the points have the coefficient vector e_k.
  const int n = 12;
  const Eigen::VectorXd x = ChebyshevPoints(n);
  for (int k = 0; k <= n; ++k) {
    Eigen::VectorXd tk(n + 1);
    for (int j = 0; j <= n; ++j) tk[j] = std::cos(k * std::acos(x[j]));
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(n + 1);
    expected[k] = 1.0;
    EXPECT_LE((ValuesToCoefficients(tk) - expected).cwiseAbs().maxCoeff(), 1e-14) << "k = " << k;
  }
}

TEST(Interpolation, ClenshawAgreesWithBarycentricAndDerivatives) {
  const int n = 40;
  const ChebyshevBasis basis(n);
  Eigen::VectorXd f(n + 1);
  for (int j = 0; j <= n; ++j) f[j] = std::exp(basis.points()[j]) * std::sin(3 * basis.points()[j]);
  const Eigen::MatrixXd c = ValuesToCoefficients(f);
  const Eigen::MatrixXd dc = DerivativeCoefficients(c);
  const Eigen::VectorXd df = DifferentiationMatrix(n) * f;
  Eigen::RowVectorXd row(n + 1), drow(n + 1);
  // Differentiation amplifies rounding by up to ||D||_inf ~ N² near the ends: 4·N²·eps·max|f|.
  const double derivative_tolerance = 4.0 * n * n * 2.2e-16 * f.cwiseAbs().maxCoeff();
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const double x = uniform(rng);
    basis.InterpolationRow(x, row);
    basis.DerivativeRow(x, drow);
    const double exact = std::exp(x) * std::sin(3 * x);
    const double exact_derivative = std::exp(x) * (std::sin(3 * x) + 3 * std::cos(3 * x));
    EXPECT_NEAR(row.dot(f), exact, 1e-14);              // degree 40 resolves this entire function
    EXPECT_NEAR(Clenshaw(c, x)[0], exact, 1e-14);
    EXPECT_NEAR(drow.dot(f), exact_derivative, derivative_tolerance);
    EXPECT_NEAR(Clenshaw(dc, x)[0], exact_derivative, derivative_tolerance);
  }
  // At the nodes the derivative row is the row of D.
  for (int j = 0; j <= n; ++j) {
    basis.DerivativeRow(basis.points()[j], drow);
    EXPECT_NEAR(drow.dot(f), df[j], derivative_tolerance);
  }
}

// Re-expanded on a sub-interval (as a cap keeps an end window's polynomial), the same polynomials:
// equal values anywhere inside it, and on their own interval the same coefficients.
TEST(Reexpand, KeepsThePolynomialsOnASubInterval) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Interval from{2.0, 7.0}, to{5.5, 6.25};
  for (const int n : {0, 1, 5, 17}) {
    Eigen::MatrixXd coefficients(n + 1, 2);
    for (Eigen::Index k = 0; k <= n; ++k) coefficients.row(k) << unit(rng), unit(rng) / (1.0 + k);
    const Eigen::MatrixXd there = Reexpand(coefficients, from, to);
    ASSERT_EQ(there.rows(), n + 1);
    for (int i = 0; i < 20; ++i) {
      const double t = 5.5 + 0.75 * (0.5 + 0.5 * unit(rng));
      const Eigen::RowVectorXd a = Clenshaw(coefficients, from.ToUnit(t)), b = Clenshaw(there, to.ToUnit(t));
      EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-13) << "degree " << n << " at " << t;
    }
    EXPECT_LT((Reexpand(coefficients, from, from) - coefficients).cwiseAbs().maxCoeff(), 1e-14) << "degree " << n;
  }
}

TEST(Interpolation, ExactNodeHitsAtHighDegree) {
  for (int n : {256, 1024, 2000}) {
    const ChebyshevBasis basis(n);
    Eigen::RowVectorXd row(n + 1);
    for (int j : {0, 1, n / 3, n / 2, n - 1, n}) {
      basis.InterpolationRow(basis.points()[j], row);
      EXPECT_EQ(row[j], 1.0);
      EXPECT_EQ(row.cwiseAbs().sum(), 1.0);  // a unit row, not NaN
    }
    // Next to a node (1 ulp away) the row is still finite and sums to 1.
    basis.InterpolationRow(std::nextafter(basis.points()[n / 3], 2.0), row);
    EXPECT_TRUE(row.allFinite());
    EXPECT_NEAR(row.sum(), 1.0, 1e-12);
  }
}

// Spectral convergence: for f analytic in the Bernstein ellipse E_rho the interpolation error
// decays like rho^-N (ATAP Thm 8.2). For the Runge function 1/(1 + 25x²), rho = (1 + sqrt(26))/5.
TEST(Interpolation, SpectralConvergenceOnRunge) {
  const double rho = (1.0 + std::sqrt(26.0)) / 5.0;
  double previous = 1.0;
  for (int n : {20, 40, 80, 160}) {
    const ChebyshevBasis basis(n);
    Eigen::VectorXd f = (1.0 / (1.0 + 25.0 * basis.points().array().square())).matrix();
    Eigen::RowVectorXd row(n + 1);
    double error = 0;
    for (int i = 0; i <= 1000; ++i) {
      const double x = -1.0 + 2.0 * i / 1000.0;
      basis.InterpolationRow(x, row);
      error = std::max(error, std::abs(row.dot(f) - 1.0 / (1.0 + 25.0 * x * x)));
    }
    // Error within a modest constant of rho^-N (down to rounding near 1e-15).
    EXPECT_LE(error, std::max(10.0 * std::pow(rho, -n), 1e-14)) << "N = " << n;
    EXPECT_LT(error, previous);
    previous = error;
  }
}

}  // namespace
}  // namespace cheval::cheb

#include "cheval/cheb/fit.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/LU>
#include <Eigen/QR>
#include <gtest/gtest.h>

#include "cheval/common/error.h"

namespace cheval::cheb {
namespace {

// Dense reference: QR of the m x (N+1) Chebyshev design matrix.
Eigen::MatrixXd DenseFit(const Eigen::VectorXd& x, const Eigen::MatrixXd& z, int degree, const Eigen::VectorXd& w) {
  Eigen::MatrixXd A(x.size(), degree + 1);
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    for (int k = 0; k <= degree; ++k) A(i, k) = std::cos(k * std::acos(std::clamp(x[i], -1.0, 1.0)));
  }
  const Eigen::VectorXd sw = w.cwiseSqrt();
  return (sw.asDiagonal() * A).colPivHouseholderQr().solve(sw.asDiagonal() * z);
}

TEST(FitLeastSquares, MatchesDenseQrWithWeightsAndJitter) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const int m = 2000, degree = 30;  // N²/m = 0.45: well conditioned
  const Interval interval{0.0, 10.0};
  Eigen::VectorXd t(m), w(m);
  Eigen::MatrixXd z(m, 3);
  for (int i = 0; i < m; ++i) {
    t[i] = 10.0 * (i + 0.3 * uniform(rng)) / m;  // jittered stamps
    w[i] = 0.5 + uniform(rng);
    z.row(i) << std::sin(t[i]) + 0.01 * normal(rng), std::cos(2 * t[i]), t[i] * t[i] * 0.1 + 0.01 * normal(rng);
  }
  const ChebyshevSeries fit = FitLeastSquares(t, z, degree, interval, &w);
  Eigen::VectorXd x(m);
  for (int i = 0; i < m; ++i) x[i] = interval.ToUnit(t[i]);
  const Eigen::MatrixXd reference = DenseFit(x, z, degree, w);
  // Normal equations lose ~cond(A) ≈ 10 digits-wise nothing here; agreement to 1e-10 is expected.
  EXPECT_LE((fit.coefficients - reference).cwiseAbs().maxCoeff(), 1e-10);
}

// One factorisation at the top degree gives every lower-degree fit: each equals the dense fit of
// that degree, and the variance factors equal diag(G⁻¹) of that block.
TEST(NestedCholesky, LeadingBlocksGiveEveryLowerDegreeFit) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  const int m = 1500, top = 40;
  const Interval interval{-1.0, 4.0};
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, -1.0, 4.0);
  Eigen::MatrixXd z(m, 2);
  for (int i = 0; i < m; ++i) z.row(i) << std::exp(-t[i] * t[i]) + 0.001 * normal(rng), std::sin(3 * t[i]);
  const NormalEquations equations = BuildNormalEquations(t, z, top, interval);
  const NestedCholesky cholesky(equations, top);
  Eigen::VectorXd x(m);
  for (int i = 0; i < m; ++i) x[i] = interval.ToUnit(t[i]);
  for (int degree : {0, 1, 5, 17, 40}) {
    const Eigen::MatrixXd reference = DenseFit(x, z, degree, Eigen::VectorXd::Ones(m));
    EXPECT_LE((cholesky.Solve(degree, equations.rhs) - reference).cwiseAbs().maxCoeff(), 1e-11) << degree;
    const Eigen::MatrixXd inverse = equations.gram.topLeftCorner(degree + 1, degree + 1).inverse();
    EXPECT_LE((cholesky.VarianceFactors(degree) - inverse.diagonal()).cwiseAbs().maxCoeff(),
              1e-12 * inverse.diagonal().cwiseAbs().maxCoeff())
        << degree;
    EXPECT_GE(cholesky.Condition(degree), 1.0);
    const int first = degree / 2;
    EXPECT_LE((cholesky.VarianceFactors(degree, first) - inverse.diagonal().tail(degree + 1 - first)).cwiseAbs().maxCoeff(),
              1e-12 * inverse.diagonal().cwiseAbs().maxCoeff())
        << degree;
  }
  EXPECT_THROW(cholesky.Solve(top + 1, equations.rhs), std::invalid_argument);
}

// A cross-validation fold's held-out errors from normal equations alone equal the squared
// residuals of each degree's training fit evaluated on the held-out samples themselves.
TEST(NestedCholesky, HeldOutErrorsEqualResidualsOnTheHeldOutSamples) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  const int m = 900, top = 30;
  const Interval interval{0.0, 9.0};
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, 9.0);
  Eigen::MatrixXd z(m, 3);
  for (int i = 0; i < m; ++i) {
    z.row(i) << std::sin(t[i]) + 0.01 * normal(rng), std::cos(3 * t[i]) + 0.01 * normal(rng), 0.1 * t[i];
  }
  std::vector<Eigen::Index> train_rows, held_rows;
  for (int i = 0; i < m; ++i) (i % 5 == 2 ? held_rows : train_rows).push_back(i);
  auto rows = [&](const std::vector<Eigen::Index>& r, const Eigen::MatrixXd& a) { return Eigen::MatrixXd(a(r, Eigen::all)); };
  const Eigen::VectorXd train_t = rows(train_rows, t), held_t = rows(held_rows, t);
  const Eigen::MatrixXd train_z = rows(train_rows, z), held_z = rows(held_rows, z);
  const NormalEquations train = BuildNormalEquations(train_t, train_z, top, interval);
  const NormalEquations held_out = BuildNormalEquationsUnchecked(held_t, held_z, top, interval);
  const NestedCholesky cholesky(train, top);
  const std::vector<int> degrees{1, 4, 9, 17, 30};
  const Eigen::MatrixXd errors =
      cholesky.HeldOutErrors(train.rhs, held_out, held_z.colwise().squaredNorm(), degrees);
  ASSERT_EQ(errors.rows(), 5);
  ASSERT_EQ(errors.cols(), 3);
  Eigen::VectorXd x(held_t.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = interval.ToUnit(held_t[i]);
  for (size_t g = 0; g < degrees.size(); ++g) {
    const Eigen::MatrixXd residual = held_z - EvaluateSeries(cholesky.Solve(degrees[g], train.rhs), x);
    for (Eigen::Index c = 0; c < 3; ++c) {
      const double expected = residual.col(c).squaredNorm();
      // Σz² − 2cᵀb + cᵀGc cancels down from Σz² (~ held-out count) to the residual: rounding of 1e-12.
      EXPECT_NEAR(errors(static_cast<Eigen::Index>(g), c), expected, 1e-12 * held_z.col(c).squaredNorm() + 1e-9 * expected)
          << "degree " << degrees[g] << " coordinate " << c;
    }
  }
  EXPECT_THROW(cholesky.HeldOutErrors(train.rhs, held_out, held_z.colwise().squaredNorm(), {top + 1}),
               std::invalid_argument);
}

TEST(FitLeastSquares, ReproducesPolynomialsExactly) {
  const int m = 500, degree = 7;
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 2.0, 5.0);
  Eigen::MatrixXd z(m, 1);
  for (int i = 0; i < m; ++i) z(i, 0) = 1.0 - 2.0 * t[i] + 0.5 * std::pow(t[i], 5) - 0.01 * std::pow(t[i], 7);
  const ChebyshevSeries fit = FitLeastSquares(t, z, degree, Interval{2.0, 5.0});
  for (double tt : {2.0, 2.5, 3.7, 5.0}) {
    const double exact = 1.0 - 2.0 * tt + 0.5 * std::pow(tt, 5) - 0.01 * std::pow(tt, 7);
    const double exact_derivative = -2.0 + 2.5 * std::pow(tt, 4) - 0.07 * std::pow(tt, 6);
    EXPECT_NEAR(fit.Value(tt)[0], exact, 1e-10 * std::abs(exact) + 1e-10);
    EXPECT_NEAR(fit.Derivative(tt)[0], exact_derivative, 1e-9 * std::abs(exact_derivative) + 1e-9);
  }
}

TEST(FitLeastSquares, TooFewSamplesIsAComputeError) {
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(5, 0.0, 1.0);
  Eigen::MatrixXd z = Eigen::MatrixXd::Zero(5, 1);
  EXPECT_THROW(FitLeastSquares(t, z, 5, Interval{0.0, 1.0}), ComputeError);
  // Enough samples but all at the same stamp: singular.
  Eigen::VectorXd same = Eigen::VectorXd::Constant(50, 0.5);
  EXPECT_THROW(FitLeastSquares(same, Eigen::MatrixXd::Zero(50, 1), 3, Interval{0.0, 1.0}), ComputeError);
}

// The moment accumulation has an unweighted kernel (no ω read, no multiplies) and sweeps two
// degrees at a time; both must give exactly the sums of the weighted kernel with unit weights
// (same terms, same order), for odd and even top degrees, partial chunks and 1..4 coordinates.
TEST(BuildNormalEquations, UnweightedKernelIsBitIdenticalToUnitWeights) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  for (const int m : {37, 512, 1500}) {
    for (const int top : {0, 1, 6, 7, 30}) {
      for (const int d : {1, 3, 4}) {
        if (m < top + 1) continue;
        const Interval interval{0.0, 3.0};
        const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, 3.0);
        Eigen::MatrixXd z(m, d);
        for (int i = 0; i < m; ++i) {
          for (int c = 0; c < d; ++c) z(i, c) = std::sin((c + 1) * t[i]) + 0.01 * normal(rng);
        }
        const Eigen::VectorXd ones = Eigen::VectorXd::Ones(m);
        const NormalEquations unweighted = BuildNormalEquations(t, z, top, interval);
        const NormalEquations weighted = BuildNormalEquations(t, z, top, interval, &ones);
        EXPECT_EQ(unweighted.gram, weighted.gram) << m << " " << top << " " << d;
        EXPECT_EQ(unweighted.rhs, weighted.rhs) << m << " " << top << " " << d;
        // And both are the sums they stand for: G_ij = Σ T_i T_j, b_k = Σ T_k z (to rounding).
        Eigen::MatrixXd basis(m, top + 1);
        for (int i = 0; i < m; ++i) {
          const double x = interval.ToUnit(t[i]);
          for (int k = 0; k <= top; ++k) basis(i, k) = std::cos(k * std::acos(std::clamp(x, -1.0, 1.0)));
        }
        EXPECT_LE((unweighted.gram - basis.transpose() * basis).cwiseAbs().maxCoeff(), 1e-10 * m);
        EXPECT_LE((unweighted.rhs - basis.transpose() * z).cwiseAbs().maxCoeff(), 1e-10 * m);
      }
    }
  }
}

// Normal equations kept by their sums build the same matrix, bit for bit, and the same
// right-hand side: the cross-validation's folds are kept that way, and their sums must be the
// matrices they replace.
TEST(NormalMoments, BuildExactlyTheNormalEquations) {
  std::mt19937_64 rng(8);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.5, 2.0);
  for (const int top : {0, 1, 2, 9, 40}) {
    const int m = 200, d = 3;
    const Interval interval{-1.0, 4.0};
    Eigen::VectorXd t(m), weights(m);
    Eigen::MatrixXd z(m, d);
    for (int i = 0; i < m; ++i) {
      t[i] = -1.0 + 5.0 * (i + 0.3 * uniform(rng)) / m;
      weights[i] = uniform(rng);
      for (int c = 0; c < d; ++c) z(i, c) = std::cos((c + 2) * t[i]) + 0.01 * normal(rng);
    }
    for (const Eigen::VectorXd* w : std::vector<const Eigen::VectorXd*>{nullptr, &weights}) {
      const NormalEquations expected = BuildNormalEquations(t, z, top, interval, w);
      const NormalMoments moments = BuildNormalMomentsUnchecked(t, z, top, interval, w);
      ASSERT_EQ(moments.sums.size(), 2 * top + 1);
      EXPECT_EQ(moments.top_degree(), top);
      EXPECT_EQ(moments.Gram(), expected.gram) << top;
      const NormalEquations equations = moments.Equations();
      EXPECT_EQ(equations.gram, expected.gram) << top;
      EXPECT_EQ(equations.rhs, expected.rhs) << top;
      EXPECT_EQ(equations.samples, m);
      EXPECT_EQ(equations.interval.a, interval.a);
      EXPECT_EQ(equations.interval.b, interval.b);
    }
  }
}

// The batch Clenshaw runs 32 independent chains at a time; each point's value must be exactly the
// one-point recurrence (Clenshaw) to rounding, including the partial last block.
TEST(EvaluateSeries, MatchesPointwiseClenshaw) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (const int n : {0, 1, 5, 120}) {
    const Eigen::MatrixXd coefficients = Eigen::MatrixXd::Random(n + 1, 3);
    for (const int m : {1, 31, 32, 33, 100}) {
      Eigen::VectorXd x(m);
      for (int i = 0; i < m; ++i) x[i] = uniform(rng);
      const Eigen::MatrixXd values = EvaluateSeries(coefficients, x);
      ASSERT_EQ(values.rows(), m);
      for (int i = 0; i < m; ++i) {
        const Eigen::RowVectorXd one = Clenshaw(coefficients, x[i]);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(values(i, c), one[c], 1e-14 * (1.0 + coefficients.cwiseAbs().sum()));
      }
    }
  }
}

}  // namespace
}  // namespace cheval::cheb

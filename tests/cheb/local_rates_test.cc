// The local interpolant's rates at defects the jump search leaves (src/cheb/local_rates.cc;
// docs/velocity.md, "Local interpolant"): a small step of the values is taken out of the slopes
// around it; a displaced sample has both of its slopes left out and takes the secant across it.
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "local_rates.h"
#include "noise_profile.h"

#include "cheval/cheb/chebyshev.h"

namespace cheval::cheb::internal {
namespace {

constexpr double kRate = 100.0, kNoise = 1e-5;

// One coordinate of smooth motion, 0.2 m/s at 0.3 Hz, sampled at the times t with noise kNoise,
// and its true rate.
struct Samples {
  Eigen::VectorXd t;
  Eigen::MatrixXd z, rate;
};

Samples Smooth(const Eigen::VectorXd& t, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, kNoise);
  const double w = 2.0 * M_PI * 0.3, amplitude = 0.2 / w;
  const Eigen::Index m = t.size();
  Samples s{t, Eigen::MatrixXd(m, 1), Eigen::MatrixXd(m, 1)};
  for (Eigen::Index i = 0; i < m; ++i) {
    s.z(i, 0) = amplitude * std::sin(w * t[i]) + gauss(rng);
    s.rate(i, 0) = amplitude * w * std::cos(w * t[i]);
  }
  return s;
}

// The same, m samples at kRate.
Samples Smooth(Eigen::Index m, uint64_t seed) {
  return Smooth(Eigen::VectorXd::LinSpaced(m, 0.0, static_cast<double>(m - 1)) / kRate, seed);
}

// The samples `kept` of a 10 Hz grid, as the curve takes their stamps: whole nanoseconds, as
// seconds from the first.
Eigen::VectorXd GridStamps(const std::vector<int64_t>& kept) {
  Eigen::VectorXd t(static_cast<Eigen::Index>(kept.size()));
  for (Eigen::Index i = 0; i < t.size(); ++i) t[i] = static_cast<double>(kept[static_cast<size_t>(i)] * 100'000'000) * 1e-9;
  return t;
}

// The rates of one run over every sample, each local with the 3-point rate (or with the 5-point
// one, and at the ends the one-sided quintic, where `five`).
Eigen::VectorXd LocalRatesOf(const Samples& s, bool five = false) {
  const Eigen::Index m = s.t.size();
  using Flags = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;
  const LocalSamples chosen{Flags::Constant(m, 1, true), Flags::Constant(m, 1, five), Flags::Constant(m, 1, false),
                            Flags::Constant(m, 1, false)};
  const Eigen::MatrixXd fit = Eigen::MatrixXd::Zero(m, 1);
  const std::vector<LocalRun> runs =
      BuildLocalRuns(s.t, s.z, 0, m, chosen, fit, fit, NoiseProfile(Eigen::VectorXd::Constant(1, kNoise)));
  EXPECT_EQ(runs.size(), 1u);
  if (runs.size() != 1 || runs.front().rates.rows() != m) return Eigen::VectorXd::Zero(m);
  return runs.front().rates.col(0);
}

// A sample displaced by ε moves both of its slopes by ε/h, opposite ways: which of the two the
// spike test found the larger was chance, and the one left in carried the displacement into the
// rate at the sample (ε/h) and at one neighbour (ε/2h). Both are left out now: the sample takes the
// secant across it, its neighbours the quadratic on their other side.
TEST(LocalRates, ADisplacedSampleLeavesBothOfItsSlopes) {
  constexpr double kDisplacement = 5e-4;  // 50σ, 0.05 m/s over a step
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    Samples s = Smooth(200, seed);
    const Eigen::Index at = 100;
    s.z(at, 0) += (seed % 2 == 0 ? 1.0 : -1.0) * kDisplacement;
    const Eigen::VectorXd rates = LocalRatesOf(s);
    const double slope_shift = kDisplacement * kRate;  // 0.05 m/s
    for (Eigen::Index i = at - 1; i <= at + 1; ++i) {
      EXPECT_LT(std::abs(rates[i] - s.rate(i, 0)), 0.1 * slope_shift) << "seed " << seed << ", sample " << i - at;
    }
  }
}

// One dropped sample of an even grid puts a step beside one twice as long: not a close pair
// (Close), whatever the steps' rounding. At a segment's end it decided whether the end sample kept
// its only slope; without it the sample took the window's rate (here 0, in a hand-held recording
// at 10 Hz with dropouts a window's 4.4 m/s where the motion is under 1 m/s). Stamps as the curve
// takes them, whole nanoseconds as seconds from the first; at 10 Hz, samples dropped beside both
// ends and on either side of one interior step.
TEST(LocalRates, AStepBesideADroppedSampleKeepsItsSlope) {
  std::vector<int64_t> kept;
  for (int64_t k = 0; k <= 50; ++k) {
    if (k != 2 && k != 20 && k != 23 && k != 48) kept.push_back(k);
  }
  const Eigen::VectorXd t = GridStamps(kept);
  const Samples s = Smooth(t, 1);
  const Eigen::VectorXd rates = LocalRatesOf(s);
  // The 3-point rates' bias on this motion at steps of 0.1–0.2 s is under 4 mm/s.
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    EXPECT_LT(std::abs(rates[i] - s.rate(i, 0)), 0.01) << "sample " << i << " at " << t[i] << " s";
  }
}

// At a segment's end, the one-sided quintic is used over steps within 1.5 of each other. A grid
// with one and then two samples dropped puts steps of 2h and 3h there, exactly 1.5 apart, and the
// steps' rounding must not decide: from the first sample of a 10 Hz grid, 0.5 − 0.2 s came out
// above 1.5 · 0.2 s, and the end sample took the one-sided quadratic, 11 mm/s off on this motion
// at both ends (the quintic's error here is under 0.5 mm/s).
TEST(LocalRates, TheOneSidedQuinticDoesNotDependOnTheStepsRounding) {
  const std::vector<int64_t> kept{0, 2, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 32, 34};
  const Eigen::VectorXd t = GridStamps(kept);
  const Samples s = Smooth(t, 1);
  const Eigen::VectorXd rates = LocalRatesOf(s, /*five=*/true);
  for (const Eigen::Index i : {Eigen::Index{0}, t.size() - 1}) {
    EXPECT_LT(std::abs(rates[i] - s.rate(i, 0)), 0.003) << "sample " << i << " at " << t[i] << " s";
  }
}

// A step δ of the values between two samples moves one slope by δ/h and departs its neighbours
// by half that the other way: only that slope is left out, and the samples on either side keep
// their rates from their own side.
TEST(LocalRates, ASmallStepLeavesOnlyItsSlope) {
  constexpr double kStep = 5e-4;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    Samples s = Smooth(200, seed);
    const Eigen::Index after = 101;
    s.z.bottomRows(s.z.rows() - after).array() += (seed % 2 == 0 ? 1.0 : -1.0) * kStep;
    const Eigen::VectorXd rates = LocalRatesOf(s);
    for (Eigen::Index i = after - 2; i <= after + 1; ++i) {
      EXPECT_LT(std::abs(rates[i] - s.rate(i, 0)), 0.1 * kStep * kRate) << "seed " << seed << ", sample " << i - after;
    }
  }
}

// The local regression scores the local interpolant's samples only where their rates carry
// noise enough (NoisyLocalSamples): white noise, or a tone at a quarter of the rate under noise of
// its amplitude, does; a tone without noise whose 3-point and 5-point rates differ by their biases
// (36 % and 15 % of its rate) far more than σ allows does not (σ a tenth of its amplitude, or its
// amplitude ten times σ: a filter's output carrying its motion from sample to sample).
TEST(LocalRates, OnlyNoisyLocalSamplesAreCalledNoisy) {
  using Flags = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;
  constexpr Eigen::Index m = 400;
  const LocalSamples all{Flags::Constant(m, 1, true), Flags::Constant(m, 1, false), Flags::Constant(m, 1, false),
                         Flags::Constant(m, 1, false)};
  auto noisy = [&](double amplitude, double noise, double sigma) {
    std::mt19937_64 rng(3);
    std::normal_distribution<double> gauss(0.0, 1.0);
    Eigen::VectorXd t(m);
    Eigen::MatrixXd z(m, 1);
    for (Eigen::Index i = 0; i < m; ++i) {
      t[i] = static_cast<double>(i) / kRate;
      z(i, 0) = amplitude * std::sin(2.0 * M_PI * kRate / 4.0 * t[i] + 0.3) + noise * gauss(rng);
    }
    return NoisyLocalSamples(t, z, 0, m, all, NoiseProfile(Eigen::VectorXd::Constant(1, sigma)))[0] != 0;
  };
  EXPECT_TRUE(noisy(0.0, kNoise, kNoise));
  EXPECT_TRUE(noisy(kNoise, kNoise, kNoise));
  EXPECT_FALSE(noisy(kNoise, 0.0, kNoise / 10.0));
  EXPECT_FALSE(noisy(10.0 * kNoise, 0.0, kNoise));
}

// A window's values, rates and second derivatives at times on its interval: those of the
// polynomial its series holds, p(t) = 2 − t + t³/2 on [1, 3], whose Chebyshev coefficients in
// x = t − 2 are 5.5, 5.375, 1.5 and 0.125.
TEST(WindowSeriesAt, GivesThePolynomialAndItsDerivatives) {
  CurveWindow window;
  window.series.interval = {1.0, 3.0};
  window.series.coefficients = Eigen::Vector4d(5.5, 5.375, 1.5, 0.125);
  window.first_derivative = DerivativeCoefficients(window.series.coefficients);
  window.second_derivative = DerivativeCoefficients(window.first_derivative);
  const Eigen::Vector3d times(1.0, 1.7, 3.0);
  const Eigen::MatrixXd values = WindowSeriesAt(window, times, 0), rates = WindowSeriesAt(window, times, 1),
                        second = WindowSeriesAt(window, times, 2);
  ASSERT_EQ(values.rows(), 3);
  for (Eigen::Index i = 0; i < times.size(); ++i) {
    const double t = times[i];
    EXPECT_NEAR(values(i, 0), 2.0 - t + 0.5 * t * t * t, 1e-13) << t;
    EXPECT_NEAR(rates(i, 0), -1.0 + 1.5 * t * t, 1e-13) << t;
    EXPECT_NEAR(second(i, 0), 3.0 * t, 1e-13) << t;
  }
  EXPECT_THROW(WindowSeriesAt(window, times, 3), std::invalid_argument);
}

}  // namespace
}  // namespace cheval::cheb::internal

#include "cheval/cheb/degree.h"

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/cheb/fit.h"
#include "synthetic_motion.h"

namespace cheval::cheb {
namespace {

// The chop's tolerance for noise-free data (curve.cc's rounding floor).
constexpr double kRounding = 1e-13;

TEST(StandardChop, FindsTheEndOfAGeometricSeries) {
  // |c_k| = 10^(-k/2) down to 1e-15 (k = 30), then a rounding plateau: resolved at about degree 30.
  Eigen::VectorXd c(60);
  for (int k = 0; k < 60; ++k) c[k] = k <= 30 ? std::pow(10.0, -k / 2.0) : 1e-15 * (1.0 + 0.3 * std::sin(k));
  const int keep = StandardChop(c, kRounding);
  EXPECT_GE(keep, 24);
  EXPECT_LE(keep, 31);
  // Without a plateau (still decaying at the end) the series is not resolved: all are kept.
  Eigen::VectorXd decaying(40);
  for (int k = 0; k < 40; ++k) decaying[k] = std::pow(10.0, -k / 10.0);
  EXPECT_EQ(StandardChop(decaying, kRounding), 40);
}

// A polynomial of degree p has exactly p + 1 nonzero coefficients; the zeros after them are the
// plateau, and the chop keeps exactly the p + 1 (worked by hand for p = 3, tol = 1e-13: the plateau
// starts at j = 5, the envelope there is set to tol^(7/6), and log10(envelope) + tilt is smallest
// at i = 5, so 4 are kept).
TEST(StandardChop, KeepsExactlyTheCoefficientsOfAPolynomial) {
  for (int p : {1, 3, 7, 20}) {
    Eigen::VectorXd c = Eigen::VectorXd::Zero(60);
    for (int k = 0; k <= p; ++k) c[k] = std::pow(0.5, k);
    EXPECT_EQ(StandardChop(c, kRounding), p + 1) << "degree " << p;
  }
}

// The same through a least-squares fit: noise-free samples of a cubic fitted at degree 40 give
// coefficients 4..40 at rounding level (~1e-16 relative), which the chop removes.
TEST(StandardChop, FindsTheDegreeOfAFittedPolynomial) {
  const Eigen::Index m = 2000;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, 2.0);
  Eigen::MatrixXd z(m, 1);
  for (Eigen::Index i = 0; i < m; ++i) z(i, 0) = 1.0 + 2.0 * t[i] - 0.7 * t[i] * t[i] + 0.3 * t[i] * t[i] * t[i];
  const ChebyshevSeries fit = FitLeastSquares(t, z, 40, Interval{0.0, 2.0});
  EXPECT_EQ(StandardChop(fit.coefficients.col(0), kRounding), 4);
}

TEST(StandardChop, EdgeCases) {
  // Fewer than 17 coefficients: the paper's test needs them, so all are kept (not resolved).
  Eigen::VectorXd shortc = Eigen::VectorXd::Zero(16);
  shortc[0] = 1.0;
  EXPECT_EQ(StandardChop(shortc, kRounding), 16);
  // A tolerance of 1 or more accepts any series as its constant term.
  EXPECT_EQ(StandardChop(Eigen::VectorXd::Ones(30), 1.0), 1);
  // An all-zero series is the constant 0.
  EXPECT_EQ(StandardChop(Eigen::VectorXd::Zero(30), kRounding), 1);
  // Signs do not matter: absolute values are used.
  Eigen::VectorXd c = Eigen::VectorXd::Zero(40);
  for (int k = 0; k <= 5; ++k) c[k] = (k % 2 ? -1.0 : 1.0) * std::pow(0.5, k);
  EXPECT_EQ(StandardChop(c, kRounding), 6);
}

// A series |c_k| = 10^(-k/4) that sinks into a noise plateau at level ε (reached at k = -4·log10 ε),
// chopped at tol = ε: the higher the noise, the fewer coefficients are kept, and the cut is at the
// start of the plateau (the tilt of step 3 may cut a few coefficients before it, never after).
TEST(StandardChop, CutsWhereTheSeriesSinksIntoTheNoise) {
  for (const auto& [level, onset] : {std::pair{1e-4, 16}, std::pair{1e-8, 32}, std::pair{1e-12, 48}}) {
    Eigen::VectorXd c(120);
    for (int k = 0; k < 120; ++k) c[k] = std::max(std::pow(10.0, -k / 4.0), level * (1.0 + 0.3 * std::sin(k)));
    const int keep = StandardChop(c, level);
    EXPECT_GE(keep, onset - 4) << level;
    EXPECT_LE(keep, onset + 1) << level;
  }
}

// For z_i = a·(-1)^i every k-th difference is (-2)^k·a·(-1)^i: |Δ^k z| = 2^k·a at every i, so the
// median is 2^k·a and the estimate is 1.4826·2^k·a / sqrt(C(2k, k)) exactly (up to rounding).
TEST(EstimateNoiseSigma, ClosedFormOnAnAlternatingSequence) {
  const Eigen::Index m = 101;
  const double a = 0.25;
  Eigen::MatrixXd z(m, 2);
  for (Eigen::Index i = 0; i < m; ++i) {
    z(i, 0) = i % 2 ? -a : a;
    z(i, 1) = 3.0 * z(i, 0);  // each column its own estimate
  }
  const Eigen::VectorXd s4 = EstimateNoiseSigma(z);  // order 4: C(8, 4) = 70
  EXPECT_NEAR(s4[0], 1.4826 * 16.0 * a / std::sqrt(70.0), 1e-15);
  EXPECT_NEAR(s4[1], 3.0 * 1.4826 * 16.0 * a / std::sqrt(70.0), 3e-15);
  const Eigen::VectorXd s2 = EstimateNoiseSigma(z, 2);  // C(4, 2) = 6
  EXPECT_NEAR(s2[0], 1.4826 * 4.0 * a / std::sqrt(6.0), 1e-15);
  const Eigen::VectorXd s1 = EstimateNoiseSigma(z, 1);  // C(2, 1) = 2
  EXPECT_NEAR(s1[0], 1.4826 * 2.0 * a / std::sqrt(2.0), 1e-15);
}

// The 4th difference of a cubic is zero: exact polynomial samples (integers here, so no rounding)
// have no noise.
TEST(EstimateNoiseSigma, ZeroOnPolynomialsOfDegreeBelowTheOrder) {
  const Eigen::Index m = 50;
  Eigen::MatrixXd z(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto x = static_cast<double>(i);
    z.row(i) << 7.0, 3.0 * x - 2.0, x * x * x - 4.0 * x * x + x;
  }
  EXPECT_EQ(EstimateNoiseSigma(z), Eigen::VectorXd::Zero(3));
  // Too few samples for a single difference of order 4: zeros.
  EXPECT_EQ(EstimateNoiseSigma(Eigen::MatrixXd::Ones(4, 2)), Eigen::VectorXd::Zero(2));
}

// White noise of σ on an oversampled smooth signal: the differences of the signal are negligible
// and the MAD of the differences estimates sqrt(70)·σ. The median of m Gaussian magnitudes has a
// relative standard error of about 1.1/sqrt(m) (differences 4 apart are independent, neighbours are
// correlated, which roughly doubles it): ~1 % at m = 20,000, so 4 % is a safe bound.
TEST(EstimateNoiseSigma, RecoversTheNoiseOfASmoothSignal) {
  std::mt19937_64 rng(11);
  const Eigen::Index m = 20000;
  for (double sigma : {1e-4, 1e-3, 2e-2}) {
    std::normal_distribution<double> noise(0.0, sigma);
    Eigen::MatrixXd z(m, 2);
    for (Eigen::Index i = 0; i < m; ++i) {
      const double t = static_cast<double>(i) * 0.005;  // 200 Hz
      z.row(i) << std::sin(0.7 * t) + noise(rng), 2.0 * std::cos(0.3 * t) + 0.1 * t + noise(rng);
    }
    const Eigen::VectorXd estimate = EstimateNoiseSigma(z);
    EXPECT_NEAR(estimate[0], sigma, 0.04 * sigma);
    EXPECT_NEAR(estimate[1], sigma, 0.04 * sigma);
  }
}

// Motion up to a tenth of the rate (40 tones at 100 Hz, 0.05 m/s each) reaches the 4th
// differences by (2 sin(ωh/2))⁴ ≈ 0.15 of its amplitude, ~15 µm against 1 µm of noise; the 6th
// and 8th take it down by 0.38 per order, and white noise leaves them at σ. Under 1 mm of noise
// the orders agree and the 4th-order estimate stands.
TEST(EstimateNoiseSigma, HigherOrdersLookPastMotionInTheUpperBand) {
  const Eigen::Index m = 4000;
  Eigen::VectorXd t(m);
  Eigen::MatrixXd motion = Eigen::MatrixXd::Zero(m, 1);
  for (Eigen::Index i = 0; i < m; ++i) {
    t[i] = static_cast<double>(i) * 0.01;
    for (int k = 1; k <= 40; ++k) {
      const double w = 2.0 * M_PI * 0.25 * k;  // 0.25..10 Hz
      motion(i, 0) += 0.05 / w * std::sin(w * t[i] + 0.7 * k * k);
    }
  }
  for (const double sigma : {1e-6, 1e-3}) {
    std::mt19937_64 rng(13);
    std::normal_distribution<double> noise(0.0, sigma);
    Eigen::MatrixXd z = motion;
    for (Eigen::Index i = 0; i < m; ++i) z(i, 0) += noise(rng);
    const double fourth = EstimateNoiseSigma(z)[0], estimate = EstimateNoiseSigma(t, z)[0];
    if (sigma < 1e-5) {
      EXPECT_GT(fourth, 5.0 * sigma);
      EXPECT_NEAR(estimate, sigma, 0.15 * sigma);
    } else {
      EXPECT_NEAR(estimate, fourth, 1e-9 * fourth);
      EXPECT_NEAR(estimate, sigma, 0.05 * sigma);
    }
  }
}

// Motion at a quarter of the rate (a 1 mm tone at 25 Hz, sampled at 100 Hz) reaches the 4th
// differences by (2 sin(π/4))⁸ = 16 in power: under 0.5 mm of noise they read ~0.6 mm. The 6th
// and 8th read it 2 and 4 times less, and white noise leaves them at σ; their drop (~10-15 %) is
// well above white noise's scatter between the orders at m = 2000 (~1.5-2 %), though not below
// 0.8 of the 4th's, which is what the estimate once needed.
TEST(EstimateNoiseSigma, HigherOrdersLookPastMotionAtAQuarterOfTheRate) {
  const Eigen::Index m = 2000;
  const double sigma = 5e-4;
  for (const uint64_t seed : {21u, 22u, 23u}) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    Eigen::VectorXd t(m);
    Eigen::MatrixXd z(m, 1);
    for (Eigen::Index i = 0; i < m; ++i) {
      t[i] = static_cast<double>(i) * 0.01;
      z(i, 0) = 1e-3 * std::sin(2.0 * M_PI * 25.0 * t[i] + 0.3) + 0.2 * std::sin(0.5 * t[i]) + noise(rng);
    }
    const double fourth = EstimateNoiseSigma(z)[0], estimate = EstimateNoiseSigma(t, z)[0];
    EXPECT_GT(fourth, 1.1 * sigma) << "seed " << seed;
    EXPECT_NEAR(estimate, sigma, 0.08 * sigma) << "seed " << seed;
  }
}

// Robust: 1 % of the samples replaced by 1 m outliers (each spoils 5 of the differences, so ~5 %
// of them) moves the median only slightly, where a standard deviation would be ~1000x too large.
TEST(EstimateNoiseSigma, OutliersBarelyMoveTheEstimate) {
  std::mt19937_64 rng(12);
  std::normal_distribution<double> noise(0.0, 1e-3);
  const Eigen::Index m = 20000;
  Eigen::MatrixXd z(m, 1);
  for (Eigen::Index i = 0; i < m; ++i) z(i, 0) = std::sin(static_cast<double>(i) * 0.005) + noise(rng);
  for (Eigen::Index i = 50; i < m; i += 100) z(i, 0) += 1.0;
  const double estimate = EstimateNoiseSigma(z)[0];
  EXPECT_GT(estimate, 1e-3);  // the outliers can only widen the distribution
  EXPECT_LT(estimate, 1.15e-3);
}

// A short recording's level comes from few differences, and the median's scatter (16 % at 100
// samples) let one draw in eight read σ a quarter low, which the residual test then takes for
// motion. Below DifferenceMagnitudes::kWinsorizedBelow samples the level is Huber's winsorized
// scale: 12 % at 100 samples, the same mean, and still bounded against a glitch (13 % however
// far off, against the median's 7 %). 400 draws of 1 s
// at 100 Hz of slow motion under 0.5 mm, each coordinate its own draw; the median's estimate
// (EstimateNoiseSigma(t, z) before the change) scattered by 0.16 here.
TEST(EstimateNoiseSigma, AShortRecordingsLevelScattersLessThanTheMedians) {
  constexpr double kSigma = 5e-4;
  constexpr Eigen::Index kSamples = 100;
  std::mt19937_64 rng(31);
  std::normal_distribution<double> noise(0.0, kSigma);
  Eigen::VectorXd t(kSamples);
  for (Eigen::Index i = 0; i < kSamples; ++i) t[i] = 0.01 * static_cast<double>(i);
  double sum = 0.0, squares = 0.0, first = 0.0, glitched = 0.0;
  int draws = 0;
  for (int draw = 0; draw < 400; ++draw) {
    Eigen::MatrixXd z(kSamples, 3);
    for (Eigen::Index i = 0; i < kSamples; ++i) {
      for (Eigen::Index c = 0; c < 3; ++c) z(i, c) = 0.2 * std::sin(1.3 * t[i] + c + draw) + noise(rng);
    }
    const Eigen::VectorXd estimate = EstimateNoiseSigma(t, z, {}) / kSigma;
    for (Eigen::Index c = 0; c < 3; ++c) sum += estimate[c], squares += estimate[c] * estimate[c], ++draws;
    first += estimate[0];
    z(kSamples / 2, 0) += 50.0 * kSigma;  // one glitch spoils 5 of the 96 differences
    glitched += EstimateNoiseSigma(t, z, {})[0] / kSigma;
  }
  const double mean = sum / draws, spread = std::sqrt(squares / draws - mean * mean);
  EXPECT_NEAR(mean, 1.0, 0.03);
  EXPECT_LT(spread, 0.14);
  EXPECT_LT((glitched - first) / 400.0, 0.15) << "a glitch of any size moves the level by about 13 %";
}

// Where the differences' tails are heavier than white noise's, they carry motion (short stretches
// of EuRoC's ground truth: µm of noise, vibration in the tails, whose winsorized scale reads
// 2.3–3x the median's), and the short recording keeps the median's estimate, which discounts it:
// taking the winsorized scale there made 60-sample stretches of EuRoC V1_02 1.08 -> 3.22 mm/s off
// EuRoC's own velocity. 150 samples of 1 µm of noise with one sample in ten jolted by 8 µm.
TEST(EstimateNoiseSigma, AShortRecordingWithHeavyTailsKeepsTheMedian) {
  constexpr Eigen::Index kSamples = 150;
  std::mt19937_64 rng(41);
  std::normal_distribution<double> noise(0.0, 1e-6), jolt(0.0, 8e-6);
  std::bernoulli_distribution jolted(0.1);
  Eigen::VectorXd t(kSamples);
  Eigen::MatrixXd z(kSamples, 1);
  for (Eigen::Index i = 0; i < kSamples; ++i) {
    t[i] = 0.005 * static_cast<double>(i);
    z(i, 0) = 0.3 * std::sin(2.0 * t[i]) + noise(rng) + (jolted(rng) ? jolt(rng) : 0.0);
  }
  const double median = EstimateNoiseSigma(z)[0];  // the 4th differences' median, evenly spaced
  const double estimate = EstimateNoiseSigma(t, z, {})[0];
  EXPECT_LE(estimate, median * (1.0 + 1e-9));
}

// Between the dropouts of a short recording the segments may be shorter than a run of the higher
// orders (9 samples for the 8th differences): such an order has no usable run and no scale, and its
// scale of 0 replaced the 4th differences' (it was "lower"), so σ read 0 and every fit interpolated
// 2 mm of noise (2 s of a car at 50 Hz with 10 dropouts of 0.1 s: 315 mm/s against central
// differences' 115; bench/velocity_short_gaps.py). Segments of 5–7 samples at 50 Hz under 2 mm.
TEST(EstimateNoiseSigma, AnOrderWithoutRunsLeavesTheLevelAlone) {
  constexpr double kSigma = 2e-3;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::vector<Eigen::Index> breaks;
  const std::vector<double> times = testing_motion::SegmentedStamps(12, &breaks);
  const auto m = static_cast<Eigen::Index>(times.size());
  const Eigen::VectorXd t = Eigen::Map<const Eigen::VectorXd>(times.data(), m);
  Eigen::MatrixXd z(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index c = 0; c < 3; ++c) z(i, c) = 0.5 * std::sin(0.7 * t[i] + c) + noise(rng);
  }
  const Eigen::VectorXd estimate = EstimateNoiseSigma(t, z, breaks) / kSigma;
  for (Eigen::Index c = 0; c < 3; ++c) {
    EXPECT_GT(estimate[c], 0.5) << "coordinate " << c;
    EXPECT_LT(estimate[c], 2.0) << "coordinate " << c;
  }
}

// The few runs of 6th differences in a short recording cut up by dropouts (one per segment of 7
// samples here) read a fifth below the 4th's by chance, and σ read low: a car at 50 Hz under 2 mm
// read 0.3 mm from one run. The level now drops to a higher order only where the three orders'
// ratios to the 4th, each counted in white noise's deviations, together show motion in the 4th
// differences. Slow motion (its 2nd differences 40 µm) under 2 mm, 100 draws: 47 of 300
// coordinates read below 0.6σ before, 8 now.
TEST(EstimateNoiseSigma, AFewHigherOrderRunsDoNotLowerTheLevelOfNoise) {
  constexpr double kSigma = 2e-3;
  std::vector<Eigen::Index> breaks;
  const std::vector<double> times = testing_motion::SegmentedStamps(12, &breaks);
  const auto m = static_cast<Eigen::Index>(times.size());
  const Eigen::VectorXd t = Eigen::Map<const Eigen::VectorXd>(times.data(), m);
  int low = 0, draws = 0;
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, kSigma);
    Eigen::MatrixXd z(m, 3);
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index c = 0; c < 3; ++c) z(i, c) = 0.5 * std::sin(0.7 * t[i] + c) + noise(rng);
    }
    const Eigen::VectorXd estimate = EstimateNoiseSigma(t, z, breaks) / kSigma;
    for (Eigen::Index c = 0; c < 3; ++c, ++draws) low += estimate[c] < 0.6 ? 1 : 0;
  }
  EXPECT_LE(low, draws / 25) << low << " of " << draws << " coordinates read σ below 0.6x the noise";
}

}  // namespace
}  // namespace cheval::cheb

#include "noise_profile.h"

#include "cheval/cheb/curve.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace cheval::cheb::internal {
namespace {

// Stamp noise (FindStampNoise). The runs of each coordinate are sorted by their squared rate and
// cut into bins of equal count: at least kMinBinRuns runs each (the median of 50 scatters by about
// a quarter in σ²), kMinBins to kMaxBins of them.
constexpr Eigen::Index kMinBinRuns = 50;
constexpr Eigen::Index kMinBins = 4;
constexpr Eigen::Index kMaxBins = 20;
// n times the variance of σ̂²/σ² for σ̂ from the median of n consecutive runs' magnitudes of white
// noise (simulated, 6,000 draws of n = 50 and 200: 4th differences 11.5 and 10.8, 8th 16.9 and
// 14.5). Every run is taken: the runs overlap, and every other run alone scatters less (6.4, 8.0).
constexpr double kBinScatter4 = 10.8;
constexpr double kBinScatter8 = 14.5;
// The slope τ² must stand this many standard errors above zero in the 4th differences, and this
// many in the 8th: on the sweep's 126 synthetic cases (no stamp noise) the 4th reached 4.3 (a
// noise-free 200 Hz recording, its 8th at −0.9), and EuRoC's ground truth 11 (its bins off the
// line, below); stamps jittered by 0.1 ms on noise-free positions score 9–22 and 15–22.
constexpr double kSlopeScore4 = 6.0;
constexpr double kSlopeScore8 = 4.0;
// The 4th differences' bins must lie on the line: a misfit (χ² per degree of freedom, from the
// bins' scatter above) of at most this (the 8th's scatter more, and need only agree in slope). Stamp noise gives 0.4–0.8; the speed-dependent noise of real
// ground truth (EuRoC 9–25, TUM-VI 8, DIDO 150–210) is something else, and a line would misplace it.
constexpr double kMaxMisfit = 3.0;
// The 8th differences' slope must agree with the 4th's to this factor either way: motion leaks
// into the differences more where it is faster, but less into the higher order (at a tenth of the
// sample rate, 8x less), while white noise reads alike in both (0.90–1.39 on jittered stamps).
constexpr double kOrderAgreement = 1.5;
// Weights come from the fitted variances, floored at this fraction of a bin's own: a line through
// zero at a noise-free recording's slow end would otherwise give its bins unbounded weight.
constexpr double kWeightFloor = 0.25;

// Rounded values (cheb::FindResolution). A difference of two values read from decimals lies within
// kResolutionUlps units in the last place of the largest of a multiple of the step, k steps k times
// the step's own error; the lattice must show within kLatticeTolerance of the step, the step
// stand kMinSteps such units above them (else any values would do), and at least
// kMinResolutionSteps differences be steps (a coordinate that hardly moves says nothing).
constexpr double kResolutionUlps = 4.0;
constexpr double kLatticeTolerance = 1e-3;
constexpr double kMinSteps = 1e3;
constexpr Eigen::Index kMinResolutionSteps = 8;
// Rounded values (cheb::IsRounded): at least this share of the runs of five that change have a
// nonzero 4th difference. Tones at 100–1000 Hz rounded to 0.1–1 mm, slowed 1–100x, give
// 0.69–1.00, and the shared TUM, EuRoC and RPNG files 0.86–0.96; motion that lies on a lattice by
// itself, only at its corners (a triangle wave of 5 mm steps at 100 Hz: 0.03; constant velocity 0).
constexpr double kRoundedShare = 0.5;
// Rounded values (RoundingLevel): the mean square of whole-step 4th differences is taken over at
// least this many runs, and only where it exceeds the one winsorized at 4 standard deviations of
// the median's estimate by at most this share: white noise's tails add 0.1 %, and so do those of
// tones rounded to 1 mm with up to 0.3 mm before (0–0.1 %), while TUM's ground truth adds 17 % to
// 1,300 times (fr1/xyz, fr2/desk) and EuRoC's 5 to 7,000 times (motion and glitches).
constexpr Eigen::Index kMinLevelRuns = 100;
constexpr double kMaxTailShare = 0.05;

// The bins' variances σ_b² against their mean squared rate u_b, fitted as s_c² + τ²·u_b by least
// squares weighted by the bins' scatter (iterated on the fitted variances).
struct SpeedLine {
  double slope = 0.0;        // τ²
  double slope_error = 0.0;  // its standard error, widened by the misfit where above 1
  double misfit = 0.0;       // χ² per degree of freedom
  Eigen::VectorXd intercept;
};

// The line for the magnitudes of runs of one order, each at the rate of its middle sample
// (`middle` samples after its first). nullopt with too few runs, or where either the magnitudes or
// the rates are zero throughout.
std::optional<SpeedLine> FitSpeedLine(const Eigen::MatrixXd& magnitudes, const Eigen::MatrixXd& rates,
                                      Eigen::Index middle, double bin_scatter, const std::vector<bool>& left_out) {
  const Eigen::Index m = magnitudes.rows(), d = magnitudes.cols();
  struct Bin {
    Eigen::Index c;
    double speed, variance, runs;
  };
  std::vector<Bin> bins;
  std::vector<std::pair<double, double>> runs;  // (squared rate, magnitude)
  std::vector<double> scratch;
  runs.reserve(static_cast<size_t>(m));
  for (Eigen::Index c = 0; c < d; ++c) {
    if (!left_out.empty() && left_out[static_cast<size_t>(c)]) continue;
    runs.clear();
    for (Eigen::Index i = 0; i + middle < m; ++i) {
      const double rate = rates(i + middle, c);
      if (!std::isnan(magnitudes(i, c))) runs.emplace_back(rate * rate, magnitudes(i, c));
    }
    const auto n = static_cast<Eigen::Index>(runs.size());
    const Eigen::Index count = std::min(kMaxBins, n / kMinBinRuns);
    if (count < kMinBins) return std::nullopt;
    // Bins of equal count in order of the squared rate, each unordered inside: the cut between
    // the middle bins first, then each half's (n·log(bins), not a sort's n·log(n)).
    const auto by_rate = [](const auto& a, const auto& b) { return a.first < b.first; };
    const auto cut = [&](const auto& self, Eigen::Index first, Eigen::Index last) -> void {
      if (last - first < 2) return;
      const Eigen::Index half = (first + last) / 2;
      const auto at = [&](Eigen::Index b) { return runs.begin() + static_cast<std::ptrdiff_t>(n * b / count); };
      std::nth_element(at(first), at(half), at(last), by_rate);
      self(self, first, half);
      self(self, half, last);
    };
    cut(cut, 0, count);
    for (Eigen::Index b = 0; b < count; ++b) {
      const Eigen::Index from = n * b / count, to = n * (b + 1) / count;
      scratch.clear();
      double speed = 0.0;
      for (Eigen::Index i = from; i < to; ++i) {
        speed += runs[static_cast<size_t>(i)].first;
        scratch.push_back(runs[static_cast<size_t>(i)].second);
      }
      const double sigma = kMadScale * SelectNonNegative(&scratch, scratch.size() / 2);
      bins.push_back({c, speed / static_cast<double>(to - from), sigma * sigma, static_cast<double>(to - from)});
    }
  }
  // A bin of exact samples has no scatter to weigh it by, and says nothing about stamp noise; a
  // coordinate left with fewer than two bins (one that does not move, or whose samples are exact)
  // leaves the fit, with no noise of its own. The others are numbered by `column`, τ² last.
  std::vector<Eigen::Index> kept(static_cast<size_t>(d), 0), column(static_cast<size_t>(d), -1);
  std::erase_if(bins, [](const Bin& bin) { return !(bin.variance > 0.0); });
  for (const Bin& bin : bins) ++kept[static_cast<size_t>(bin.c)];
  Eigen::Index columns = 0;
  for (Eigen::Index c = 0; c < d; ++c) {
    if (kept[static_cast<size_t>(c)] >= 2) column[static_cast<size_t>(c)] = columns++;
  }
  std::erase_if(bins, [&column](const Bin& bin) { return column[static_cast<size_t>(bin.c)] < 0; });
  if (columns == 0) return std::nullopt;
  // In units of the largest variance and squared rate, so that neither tiny nor huge values
  // reach the weights.
  double variance_unit = 0.0, speed_unit = 0.0;
  for (const Bin& bin : bins) {
    variance_unit = std::max(variance_unit, bin.variance);
    speed_unit = std::max(speed_unit, bin.speed);
  }
  if (!(variance_unit > 0.0) || !(speed_unit > 0.0) || !std::isfinite(variance_unit) || !std::isfinite(speed_unit)) {
    return std::nullopt;
  }
  const auto count = static_cast<Eigen::Index>(bins.size());
  Eigen::VectorXd y(count), u(count), fitted(count), weight(count);
  for (Eigen::Index j = 0; j < count; ++j) {
    y[j] = bins[static_cast<size_t>(j)].variance / variance_unit;
    u[j] = bins[static_cast<size_t>(j)].speed / speed_unit;
  }
  fitted = y;
  const Eigen::Index k = columns;  // τ²'s column
  if (count - k - 1 < 2) return std::nullopt;  // too few bins to tell a line from its scatter
  Eigen::MatrixXd normal(k + 1, k + 1);
  Eigen::VectorXd rhs(k + 1), theta(k + 1), scale(k + 1);
  double inverse_kk = 0.0;  // (normal⁻¹)_kk: τ²'s variance in the units below
  for (int iteration = 0; iteration < 3; ++iteration) {
    normal.setZero();
    rhs.setZero();
    for (Eigen::Index j = 0; j < count; ++j) {
      const Bin& bin = bins[static_cast<size_t>(j)];
      const Eigen::Index a = column[static_cast<size_t>(bin.c)];
      const double f = std::max(fitted[j], kWeightFloor * y[j]);
      weight[j] = bin.runs / (bin_scatter * f * f);
      normal(a, a) += weight[j];
      normal(a, k) += weight[j] * u[j];
      normal(k, k) += weight[j] * u[j] * u[j];
      rhs[a] += weight[j] * y[j];
      rhs[k] += weight[j] * y[j] * u[j];
    }
    for (Eigen::Index a = 0; a < k; ++a) normal(k, a) = normal(a, k);
    // Solved scaled to a unit diagonal: weights go as 1/σ⁴, and a coordinate far quieter than the
    // others would make the raw matrix look singular while the line is well determined.
    scale = normal.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(scale.asDiagonal() * normal * scale.asDiagonal());
    if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-12) || !scale.allFinite()) return std::nullopt;
    theta = scale.asDiagonal() * ldlt.solve(scale.asDiagonal() * rhs);
    inverse_kk = scale[k] * scale[k] * ldlt.solve(Eigen::VectorXd::Unit(k + 1, k))[k];
    for (Eigen::Index j = 0; j < count; ++j) {
      fitted[j] = theta[column[static_cast<size_t>(bins[static_cast<size_t>(j)].c)]] + theta[k] * u[j];
    }
  }
  SpeedLine line;
  double chi2 = 0.0;
  for (Eigen::Index j = 0; j < count; ++j) chi2 += weight[j] * (y[j] - fitted[j]) * (y[j] - fitted[j]);
  line.misfit = chi2 / static_cast<double>(count - k - 1);
  line.slope = theta[k] * variance_unit / speed_unit;
  line.slope_error = std::sqrt(std::max(inverse_kk, 0.0) * std::max(line.misfit, 1.0)) * variance_unit / speed_unit;
  line.intercept = Eigen::VectorXd::Zero(d);
  for (Eigen::Index c = 0; c < d; ++c) {
    if (column[static_cast<size_t>(c)] >= 0) line.intercept[c] = theta[column[static_cast<size_t>(c)]] * variance_unit;
  }
  return line;
}

}  // namespace

std::optional<StampNoise> FindStampNoise(const DifferenceMagnitudes& magnitudes, const std::vector<bool>& left_out) {
  const std::optional<SpeedLine> fourth =
      FitSpeedLine(magnitudes.fourth(), magnitudes.rates(), 2, kBinScatter4, left_out);
  if (!fourth || !(fourth->slope >= kSlopeScore4 * fourth->slope_error) || !(fourth->misfit <= kMaxMisfit)) {
    return std::nullopt;
  }
  const std::optional<SpeedLine> eighth =
      FitSpeedLine(magnitudes.eighth(), magnitudes.rates(), 4, kBinScatter8, left_out);
  if (!eighth || !(eighth->slope >= kSlopeScore8 * eighth->slope_error)) return std::nullopt;
  if (!(eighth->slope <= kOrderAgreement * fourth->slope && fourth->slope <= kOrderAgreement * eighth->slope)) {
    return std::nullopt;
  }
  // The lower of the two: what leaks of the motion only ever adds.
  const SpeedLine& line = eighth->slope < fourth->slope ? *eighth : *fourth;
  return StampNoise{line.slope, line.intercept.cwiseMax(0.0)};
}

NoiseProfile::NoiseProfile(const Eigen::VectorXd& level) : level_(level), maximum_(level) {}

NoiseProfile::NoiseProfile(const Eigen::VectorXd& level, const DifferenceMagnitudes& magnitudes, Eigen::Index m,
                           const Eigen::VectorXd& rounded)
    : level_(level), maximum_(level) {
  const Eigen::Index d = level.size();
  std::vector<bool> dominated(static_cast<size_t>(d), false);
  for (Eigen::Index c = 0; c < d; ++c) dominated[static_cast<size_t>(c)] = RoundingDominates(level[c], rounded[c]);
  stamp_noise_ = FindStampNoise(magnitudes, dominated);
  if (stamp_noise_) {
    for (Eigen::Index c = 0; c < d; ++c) {
      if (dominated[static_cast<size_t>(c)]) stamp_noise_->intercept[c] = level[c] * level[c];
    }
  }
  // The variance the blocks are judged against, per sample: the level's, or the stamp noise's.
  // `base` holds the latter's running sums ((m + 1) x d); empty for the level.
  const Eigen::VectorXd level_variance = level.cwiseAbs2();
  auto base_at = [&](Eigen::Index i, Eigen::Index c) {
    if (!stamp_noise_) return level_variance[c];
    const double rate = magnitudes.rates()(i, c);
    return stamp_noise_->intercept[c] + stamp_noise_->variance * (rate * rate);
  };
  Eigen::MatrixXd base;
  if (stamp_noise_) {
    base = Eigen::MatrixXd::Zero(m + 1, d);
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index c = 0; c < d; ++c) base(i + 1, c) = base(i, c) + base_at(i, c);
    }
  }
  // The base's RMS σ over samples [from, to).
  auto base_over = [&](Eigen::Index from, Eigen::Index to) -> Eigen::VectorXd {
    if (base.size() == 0) return level;
    return ((base.row(to) - base.row(from)).transpose() / static_cast<double>(to - from)).cwiseMax(0.0).cwiseSqrt();
  };
  cumulative_ = Eigen::MatrixXd::Zero(m + 1, d);
  const Eigen::VectorXd raise = kRaise * level, burst = kBurst * level;
  // Where the 4th differences' median over a stretch cannot exceed a threshold (their counts say
  // so), no median is taken; a threshold that varies along the samples is not counted.
  Eigen::MatrixXi counts, burst_counts;
  if (base.size() == 0) {
    counts = magnitudes.CountsAbove(raise, kBlock), burst_counts = magnitudes.CountsAbove(burst, kBlock);
  }
  // Stretches start and end at blocks' starts or at the end: rows of the counts.
  auto row = [](Eigen::Index sample) { return (sample + kBlock - 1) / kBlock; };
  auto may_exceed = [d, &row](const Eigen::MatrixXi& above_counts, Eigen::Index from, Eigen::Index to) {
    if (above_counts.size() == 0) return true;
    for (Eigen::Index c = 0; c < d; ++c) {
      const int usable = above_counts(row(to), 2 * c) - above_counts(row(from), 2 * c);
      const int above = above_counts(row(to), 2 * c + 1) - above_counts(row(from), 2 * c + 1);
      if (usable > 0 && above >= usable - usable / 2) return true;
    }
    return false;
  };
  const Eigen::Index blocks = (m + kBlock - 1) / kBlock;
  Eigen::VectorXd largest = Eigen::VectorXd::Zero(d);  // the largest variance per coordinate
  Eigen::MatrixXd bursts = Eigen::MatrixXd::Zero(blocks, d);
  for (Eigen::Index b = 0; b < blocks; ++b) {
    // The last block, when short, is judged with the one before it: over its few differences the
    // estimate scatters past kBurst, and the higher orders, which see past the motion, have fewer
    // runs or none (a chirp's fastest end read as a burst).
    const Eigen::Index end = std::min(m, (b + 1) * kBlock);
    const Eigen::Index begin = (b > 0 && end - b * kBlock < kBlock) ? (b - 1) * kBlock : b * kBlock;
    if (!may_exceed(burst_counts, begin, end)) continue;
    const Eigen::VectorXd threshold = kBurst * base_over(begin, end);
    const Eigen::VectorXd own = magnitudes.SigmaIfAbove(begin, end, threshold);
    for (Eigen::Index c = 0; c < d; ++c) {
      if (own[c] > threshold[c]) bursts(b, c) = own[c];
    }
  }
  for (Eigen::Index begin = 0; begin < m; begin += kBlock) {
    const Eigen::Index end = std::min(m, begin + kBlock);
    const Eigen::Index from = std::max<Eigen::Index>(0, begin - kPooledBlocks * kBlock);
    const Eigen::Index to = std::min(m, end + kPooledBlocks * kBlock);
    const Eigen::VectorXd pooled = base_over(from, to), threshold = kRaise * pooled;
    Eigen::VectorXd local = may_exceed(counts, from, to) ? magnitudes.SigmaIfAbove(from, to, threshold) : pooled;
    // A burst shorter than half the pool leaves its median; the block's own estimate shows it,
    // and the blocks beside it take it too (a burst's edge half fills its block, whose own
    // estimate may stay below the threshold while its windows fit the burst's noise).
    const Eigen::Index b = begin / kBlock;
    for (Eigen::Index k = std::max<Eigen::Index>(0, b - 1); k <= std::min(blocks - 1, b + 1); ++k) {
      local = local.cwiseMax(bursts.row(k).transpose());
    }
    // A sample's variance is base · factor² + own. Raised over stamp noise, a block keeps the
    // base's course with the speed, scaled by the factor the local σ stands above the pool's RMS;
    // raised over the level (or over a base of 0: no noise of its own, no motion there), it takes
    // the local σ as it is.
    Eigen::VectorXd factor = Eigen::VectorXd::Ones(d), own = Eigen::VectorXd::Zero(d);
    bool raised = false;
    for (Eigen::Index c = 0; c < d; ++c) {
      if (!(local[c] > threshold[c])) continue;
      raised = true;
      if (stamp_noise_ && pooled[c] > 0.0) {
        factor[c] = local[c] / pooled[c];
      } else {
        factor[c] = 0.0;
        own[c] = local[c] * local[c];
      }
    }
    if (raised) raised_samples_ += end - begin;
    raised_blocks_.push_back(raised ? 1 : 0);
    for (Eigen::Index i = begin; i < end; ++i) {
      for (Eigen::Index c = 0; c < d; ++c) {
        const double variance = base_at(i, c) * factor[c] * factor[c] + own[c];
        largest[c] = std::max(largest[c], variance);
        cumulative_(i + 1, c) = cumulative_(i, c) + variance;
      }
    }
  }
  maximum_ = maximum_.cwiseMax(largest.cwiseSqrt());
  if (raised_samples_ == 0 && !stamp_noise_) cumulative_.resize(0, 0);
}

Eigen::VectorXd NoiseProfile::Over(Eigen::Index first, Eigen::Index count) const {
  if (count <= 0 || cumulative_.size() == 0) return level_;
  const Eigen::RowVectorXd sum = cumulative_.row(first + count) - cumulative_.row(first);
  return (sum.transpose() / static_cast<double>(count)).cwiseMax(0.0).cwiseSqrt();
}

}  // namespace cheval::cheb::internal

namespace cheval::cheb {

double FindResolution(const Eigen::Ref<const Eigen::VectorXd>& z) {
  double scale = 0.0;
  for (const double value : z) {
    if (!std::isfinite(value)) return 0.0;
    scale = std::max(scale, std::abs(value));
  }
  // Two values read from decimals differ from a multiple of their step by about a unit in the
  // last place of the largest; the step itself is the smallest difference, to that unit too.
  const double slack = internal::kResolutionUlps * std::numeric_limits<double>::epsilon() * scale;
  double q = std::numeric_limits<double>::infinity();
  Eigen::Index steps = 0;
  for (Eigen::Index i = 1; i < z.size(); ++i) {
    const double difference = std::abs(z[i] - z[i - 1]);
    if (difference <= slack) continue;
    ++steps;
    q = std::min(q, difference);
  }
  if (steps < internal::kMinResolutionSteps || !(q >= internal::kMinSteps * slack)) return 0.0;
  double total = 0.0, total_steps = 0.0;
  for (Eigen::Index i = 1; i < z.size(); ++i) {
    const double difference = std::abs(z[i] - z[i - 1]);
    if (difference <= slack) continue;
    // k steps carry k times the step's own error; where that nears the step, no lattice can be told.
    const double k = std::round(difference / q), tolerance = (k + 1.0) * slack;
    if (tolerance > internal::kLatticeTolerance * q || std::abs(difference - k * q) > tolerance) return 0.0;
    total += difference;
    total_steps += k;
  }
  return total / total_steps;  // the step from every difference, not from the smallest alone
}

bool IsRounded(const Eigen::Ref<const Eigen::VectorXd>& values, double q) {
  return q > 0.0 && values.size() >= 5 && internal::IsRoundedSteps(internal::WholeSteps(values, q));
}

}  // namespace cheval::cheb

namespace cheval::cheb::internal {
namespace {

// The 4th difference of whole steps over samples i..i + 4 (exact: the steps are whole numbers).
double FourthDifference(const Eigen::VectorXd& steps, Eigen::Index i) {
  return steps[i] - 4.0 * steps[i + 1] + 6.0 * steps[i + 2] - 4.0 * steps[i + 3] + steps[i + 4];
}

}  // namespace

bool IsRoundedSteps(const Eigen::VectorXd& steps) {
  Eigen::Index changing = 0, scattered = 0;
  for (Eigen::Index i = 0; i + 4 < steps.size(); ++i) {
    const double first = steps[i];
    if (first == steps[i + 1] && first == steps[i + 2] && first == steps[i + 3] && first == steps[i + 4]) continue;
    ++changing;
    if (FourthDifference(steps, i) != 0.0) ++scattered;
  }
  return changing > 0 && static_cast<double>(scattered) >= kRoundedShare * static_cast<double>(changing);
}

Eigen::VectorXd WholeSteps(const Eigen::Ref<const Eigen::VectorXd>& values, double q) {
  Eigen::VectorXd n(values.size());
  for (Eigen::Index i = 0; i < values.size(); ++i) n[i] = std::round((values[i] - values[0]) / q);
  return n;
}

double RoundingLevel(const Eigen::VectorXd& steps, double q, const std::vector<Eigen::Index>& breaks) {
  const double floor = q / std::sqrt(12.0);
  // The 4th differences of the runs of five that no break crosses, in steps.
  std::vector<double> fourth;
  fourth.reserve(static_cast<size_t>(steps.size()));
  size_t next = 0;  // the first break at or after the run's first sample
  for (Eigen::Index i = 0; i + 4 < steps.size(); ++i) {
    while (next < breaks.size() && breaks[next] < i) ++next;
    if (next < breaks.size() && breaks[next] < i + 4) continue;
    fourth.push_back(std::abs(FourthDifference(steps, i)));
  }
  const auto runs = static_cast<double>(fourth.size());
  if (fourth.size() < static_cast<size_t>(kMinLevelRuns)) return floor;
  double square = 0.0;
  for (const double f : fourth) square += f * f;
  square /= runs;
  // White noise's 4th differences have 70 times its variance.
  const double scale = std::sqrt(70.0);
  std::vector<double> scratch = fourth;
  const double median = kMadScale * SelectNonNegative(&scratch, scratch.size() / 2) / scale;  // σ in steps
  const double start = std::max(median, 1.0 / std::sqrt(12.0));
  if (!(start < 1.0 / std::sqrt(3.0))) return floor;
  const double clip = 4.0 * scale * start;
  double winsorized = 0.0;
  for (const double f : fourth) winsorized += std::min(f, clip) * std::min(f, clip);
  winsorized /= runs;
  if (square > (1.0 + kMaxTailShare) * winsorized) return floor;
  return std::max(floor, q * std::sqrt(square / 70.0));
}

}  // namespace cheval::cheb::internal

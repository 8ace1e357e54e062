#pragma once
// Internal to the cheb library: the noise level along a curve's samples. Real motion capture is
// noisier over some stretches than others: the data's level, a median over all the samples, is
// the quiet stretches' (docs/velocity.md, "Noise profile").

#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace cheval::cheb::internal {

/// The factor from a median absolute value to a normal distribution's σ.
inline constexpr double kMadScale = 1.4826;

/// The k-th smallest (from 0, k < size) of `values`, which are non-negative (not −0) and not NaN,
/// as std::nth_element finds it; `values` may be reordered and shrunk.
double SelectNonNegative(std::vector<double>* values, size_t k);

/// The magnitudes of the 2nd, 4th, 6th and 8th divided differences of every run of 3, 5, 7 and 9
/// consecutive samples (EstimateNoiseSigma(t, z, breaks), which is built on it in degree.cc),
/// kept per run so that the estimate can be taken over any stretch of the samples.
class DifferenceMagnitudes {
 public:
  /// The three orders are taken on up to `threads` threads.
  DifferenceMagnitudes(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                       const std::vector<Eigen::Index>& breaks, int threads = 1);

  /// EstimateNoiseSigma's estimate from the runs that start at samples [begin, end): kMadScale ·
  /// the median magnitude, or over fewer than kWinsorizedBelow samples Huber's winsorized scale
  /// where the differences' tails are white noise's, lowered to a higher order's only where the
  /// orders together show motion in the 4th differences (docs/velocity.md, "Noise estimate").
  Eigen::VectorXd Sigma(Eigen::Index begin, Eigen::Index end) const;
  /// The median's estimate where it exceeds `threshold` (per coordinate); elsewhere a value no
  /// larger than `threshold`: the 4th differences' estimate, which the higher orders only ever
  /// lower. A third of the cost where a stretch is not noisier.
  Eigen::VectorXd SigmaIfAbove(Eigen::Index begin, Eigen::Index end, const Eigen::VectorXd& threshold) const;
  /// For telling where SigmaIfAbove can exceed `threshold` without a median, over stretches that
  /// start and end at multiples of `stride` (or at the last sample): per coordinate c, the number
  /// of usable runs starting before sample k·stride (row k; the last row: before the end, m) in
  /// column 2c, and of those whose 4th differences' scaled magnitude exceeds threshold[c] in
  /// column 2c + 1; ⌈m / stride⌉ + 1 rows x 2d. Over a stretch of n usable runs, the 4th
  /// differences' estimate exceeds the threshold exactly when n − ⌊n/2⌋ of them do.
  Eigen::MatrixXi CountsAbove(const Eigen::VectorXd& threshold, Eigen::Index stride) const;

  /// The magnitudes of the 4th and 8th divided differences by run start (m x d, NaN where no usable
  /// run starts; kMadScale times their median is σ).
  const Eigen::MatrixXd& fourth() const { return fourth_; }
  const Eigen::MatrixXd& eighth() const { return eighth_; }
  /// A rate per sample and coordinate (m x d): the secant over the samples up to two on either side
  /// that no boundary separates from it; 0 where it has no neighbour at another stamp, or where a
  /// value is not finite.
  const Eigen::MatrixXd& rates() const { return rates_; }

  /// Below this many samples the median's scatter exceeds what the residual test's 10 % margin
  /// covers (about m/6 degrees of freedom: under 50), and Sigma takes Huber's winsorized scale,
  /// with m/3, where it agrees with the median's. Longer stretches keep the median: motion in the
  /// differences' tails (EuRoC's vibration) reaches a mean of squares far more than the median.
  static constexpr Eigen::Index kWinsorizedBelow = 300;

 private:
  // `drops_need_evidence`: a higher order lowers the estimate only where the orders together show
  // motion in the 4th differences (the level); else wherever it is lower by more than white noise's
  // scatter allows (a stretch's raise over the level, which a drop only ever withholds).
  Eigen::VectorXd Estimate(Eigen::Index begin, Eigen::Index end, const Eigen::VectorXd& threshold,
                           bool winsorized, bool drops_need_evidence) const;

  Eigen::MatrixXd second_, fourth_, sixth_, eighth_;  // m x d, NaN where no usable run starts
  Eigen::MatrixXd rates_;
};

/// Noise from the stamps (docs/velocity.md, "Stamp noise"): samples taken at t_i + δ_i but stamped
/// t_i, with white δ of RMS τ, are off by v(t_i)·δ_i: white noise whose variance grows with the
/// speed, σ_c²(i) = s_c² + τ²·v_c(t_i)², s_c the positions' own noise.
struct StampNoise {
  double variance = 0.0;      // τ² in s²
  Eigen::VectorXd intercept;  // s_c² per coordinate (never negative)
};

/// Stamp noise, where the differences' magnitudes show it: the 4th differences' variance in bins
/// of speed lies on a line in the squared rate, steeply enough to be told from the bins' scatter,
/// and the 8th differences' slope agrees (motion's leak into them grows with the speed too, but
/// falls with the order, while white noise's does not). nullopt where they do not, and below a few
/// hundred samples. Coordinates marked in `left_out` (empty: none) take no part: their errors
/// change with the speed for another reason (RoundingDominates), and their intercept is 0.
std::optional<StampNoise> FindStampNoise(const DifferenceMagnitudes& magnitudes,
                                         const std::vector<bool>& left_out = {});

/// The values of a coordinate on a lattice of step q, as whole numbers of steps from the first
/// (exact: FindResolution put them there). FitCurve takes them once per coordinate for the
/// three uses below.
Eigen::VectorXd WholeSteps(const Eigen::Ref<const Eigen::VectorXd>& values, double q);

/// cheb::IsRounded on the values' whole steps (WholeSteps).
bool IsRoundedSteps(const Eigen::VectorXd& steps);

/// The noise σ of values rounded to steps of q (cheb::IsRounded) that the fit floors an estimate
/// at: q/sqrt(12), or more where the noise added before the rounding shows. Rounding x + n, n white
/// of σ_n, errs by u + n with u uniform over a step and independent of n wherever the motion
/// crosses many steps, so the values' noise is sqrt(q²/12 + σ_n²). Where σ_n is below about q/2
/// the median of their whole-step 4th differences is a few steps at most and reads it coarsely (0,
/// 0.18, 0.35, … steps; noise of q/5 before rounding slow motion: 0 for a noise of 0.35·q), while
/// their mean square reads it to a few per cent: it is taken where the median reads below q/sqrt(3)
/// and the differences have no tails beyond 4 of the median's standard deviations (mean square
/// within kMaxTailShare of the one with those winsorized). EuRoC's and TUM's ground truth keep
/// q/sqrt(12): their medians read above q/sqrt(3), or their tails (motion and glitches) are heavy.
/// `steps`: the values in whole steps (WholeSteps); `breaks`: boundaries b (between samples b and
/// b + 1) no difference is taken across.
double RoundingLevel(const Eigen::VectorXd& steps, double q, const std::vector<Eigen::Index>& breaks);

/// Whether a coordinate rounded to steps of q (0: none) at noise level `sigma` has errors the
/// rounding dominates: σ below q/sqrt(3), the values' noise with white noise of q/2 before the
/// rounding, below which the rounding's errors change with the motion's speed (a staircase where it
/// is slow, white where it is fast). Its differences growing with the speed say nothing of stamps.
inline bool RoundingDominates(double sigma, double q) { return q > 0.0 && sigma < q / std::sqrt(3.0); }

/// Whether a noise σ (a profile's RMS over some samples) is the rounding's, `rounding` =
/// q/sqrt(12) from cheb::FindResolution (0: none), to which an estimate was floored: the differences
/// read less, on a staircase whose errors are correlated from sample to sample, or through a
/// median of whole-step differences that reads low. (The RMS over a stretch differs from the
/// floor in the last bits.)
inline bool AtRoundingLevel(double sigma, double rounding) {
  return rounding > 0.0 && std::abs(sigma - rounding) <= 1e-9 * rounding;
}

/// The noise σ per coordinate along the samples: the data's level, raised over blocks of
/// kBlock samples whose own estimate, pooled over kPooledBlocks blocks on either side, exceeds it
/// by more than kRaise (a factor the estimate's scatter over that many samples does not reach on
/// stationary noise), or whose estimate over the block alone exceeds it by more than kBurst (the
/// same for the block's scatter, far wider): a burst of noise shorter than half the pool, which
/// its median does not see (TUM fr2/desk's motion capture: tens of samples at ~10x the level).
/// That raise covers the blocks on either side as well: a burst's edges half fill theirs. The last
/// block, when shorter than kBlock, is judged for a burst with the block before it.
class NoiseProfile {
 public:
  static constexpr Eigen::Index kBlock = 32;
  static constexpr Eigen::Index kPooledBlocks = 2;
  static constexpr double kRaise = 1.5;
  static constexpr double kBurst = 3.0;

  /// The level everywhere.
  explicit NoiseProfile(const Eigen::VectorXd& level);
  /// The level, raised where the samples' `magnitudes` say they are noisier. Where they show stamp
  /// noise (FindStampNoise), its σ_c(i) takes the level's place, and is raised by the same rules
  /// against its own RMS.
  /// `rounded` per coordinate: the step its values were rounded to (0: none); coordinates whose
  /// errors the rounding dominates (RoundingDominates) are left out of the search for stamp noise,
  /// and keep their level under it.
  NoiseProfile(const Eigen::VectorXd& level, const DifferenceMagnitudes& magnitudes, Eigen::Index m,
               const Eigen::VectorXd& rounded);

  /// The root mean square of σ over samples [first, first + count), per coordinate.
  Eigen::VectorXd Over(Eigen::Index first, Eigen::Index count) const;
  /// The data's level.
  const Eigen::VectorXd& level() const { return level_; }
  /// Samples in blocks raised above the base (the level, or the stamp noise's σ) in some coordinate.
  Eigen::Index raised_samples() const { return raised_samples_; }
  /// The largest σ per coordinate, never below the level (the level where nothing is raised).
  const Eigen::VectorXd& maximum() const { return maximum_; }
  /// The stamp noise found, if any.
  const std::optional<StampNoise>& stamp_noise() const { return stamp_noise_; }
  /// Whether σ differs from the level anywhere (raised, or stamp noise).
  bool varies() const { return cumulative_.size() > 0; }
  /// Whether block b (samples [b·kBlock, (b + 1)·kBlock)) was raised above the base.
  bool BlockRaised(Eigen::Index b) const {
    return b >= 0 && b < static_cast<Eigen::Index>(raised_blocks_.size()) && raised_blocks_[static_cast<size_t>(b)];
  }

 private:
  Eigen::VectorXd level_, maximum_;
  std::optional<StampNoise> stamp_noise_;
  Eigen::MatrixXd cumulative_;  // (m + 1) x d: Σ σ² over the samples before each row; empty: the level
  Eigen::Index raised_samples_ = 0;
  std::vector<char> raised_blocks_;
};

}  // namespace cheval::cheb::internal

#pragma once
/// \file
/// A continuous-time curve fitted to stamped samples: overlapping windowed Chebyshev least-squares
/// fits with automatically chosen degrees, blended smoothly, split at gaps. Gives position,
/// velocity and acceleration at any time inside the data (the C-ASE ground-truth velocity).

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "cheval/common/progress.h"
#include "cheval/cheb/fit.h"

namespace cheval::cheb {

/// How the degree of each window is chosen.
enum class DegreeMethod {
  /// 5-fold cross-validation over a geometric grid of degrees, per coordinate (default: the most
  /// accurate velocity of the automatic rules, docs/velocity.md "Accuracy").
  kCrossValidation,
  /// Chebfun's standardChop on a high-degree fit, tolerance σ·sqrt(2/m) relative to the largest
  /// varying coefficient, σ the (estimated) noise: about half the time of cross-validation, with a
  /// larger velocity error on noisy data (docs/velocity.md "Accuracy", column "chop").
  kChop,
  kFixed,  ///< the given degree in every window
};

/// Options of FitCurve; defaults need no tuning. Validate() is called by FitCurve.
struct CurveOptions {
  DegreeMethod degree_method = DegreeMethod::kCrossValidation;
  /// kFixed: the degree. With a single window this is the classic global fit.
  int fixed_degree = 0;
  /// Fixed window length (s); nullopt = adaptive: windows are halved until their series resolve.
  std::optional<double> window_s;
  /// Upper bound of N²/m in a window: beyond it equispaced least squares is ill-conditioned
  /// (docs/velocity.md "Formulas": N²/m = 8 -> condition ~15, 32 -> 2e5).
  double max_conditioning = 8.0;
  /// Largest degree tried in a window.
  int max_degree = 400;
  /// Windows are not split below this many samples: with the lack-of-fit test, nearly noise-free
  /// data with fine motion end in short windows at a high relative degree (the σ → 0 limit, a
  /// local interpolant); noisy fits rarely come near it (docs/velocity.md).
  int min_window_samples = 12;
  /// Each window extends beyond its core by this fraction of the core on both sides.
  double overlap = 0.25;
  /// A stamp difference larger than both gap_factor x the median difference and min_gap_s splits
  /// the data into segments that are fitted separately (no polynomial bridges a long gap). A lone
  /// sample between two gaps joins the neighbour across the shorter gap.
  double gap_factor = 4.0;
  double min_gap_s = 0.1;
  /// Noise standard deviation of the samples (same unit as them); nullopt = estimated from the data.
  std::optional<double> noise_sigma;
  /// The step the values were rounded to, where the caller knows it; 0: per coordinate, the
  /// lattice the values lie on, if any (FindResolution). An estimated σ is at least step/sqrt(12),
  /// more where noise was added before the rounding (docs/velocity.md, "Rounded positions").
  /// Rotation charts of rounded quaternions lie on no lattice of their own, and take it from the
  /// quaternions' (eval::EstimateVelocity). A found lattice floors σ only where the values were
  /// rounded to it (IsRounded); a given one always.
  double resolution = 0.0;
  /// The derivative of a least-squares polynomial is noisiest at the ends of its interval, and
  /// more so the higher its degree (the variance at an end grows like N⁴/m). The first and last
  /// window of every segment are therefore halved until their degree is at most end_degree (or
  /// they reach min_window_samples): a graded mesh towards the ends. 0 disables it. The default 20
  /// gives the lowest full-range velocity error over the synthetic kinds of docs/velocity.md.
  int end_degree = 20;
  /// Then give each end of a segment a short low-degree "cap" where that is estimated to lower the
  /// velocity error: the cap's length, blending boundary and degrees are chosen by one-sided fits
  /// at artificial ends inside the segment, checked against the curve's interior velocity there
  /// (docs/velocity.md, "End caps"). Adaptive windows only (not with window_s, single_window or a
  /// fixed degree, which ask for a literal fit). At a gap, a fit across it takes over a segment's
  /// end where the data on both sides say it is the better estimate (docs/velocity.md, "Gaps";
  /// WindowVerdict::kBridge). false keeps the end windows' own polynomials.
  bool end_caps = true;
  /// With end_caps, segments of one or two windows (or with too little room between their end
  /// windows to judge a cap there) get caps too: chosen at artificial ends inside
  /// the end window, where its own rate is the reference, and against its rate's variance at the
  /// end, σ²·dᵀG⁻¹d with the window's σ. The angular fit turns it off: its charts' noise varies
  /// along them (largest at their ends), and a chart's end lies where it is blended with the next.
  bool short_segment_caps = true;
  /// Fit a single window over each gap-free segment (no splitting), e.g. to reproduce a global fit.
  bool single_window = false;
  /// Find isolated defects before fitting (docs/velocity.md, "Jumps and glitches"): a sample
  /// displaced from both of its neighbours is left out of the fit (an outlier); a step of the
  /// values between two samples across which the rate goes on is taken out of the samples and
  /// added back to the curve's values (its derivatives do not see it); a jump of the rate splits the
  /// data there as a gap does. None of them spreads over a window. Only departures far beyond the local scatter count (6 local
  /// scales): on clean data next to nothing is found. false fits every sample as given.
  bool robust = true;
  /// A window is accepted only when its residual is consistent with the noise too (the
  /// lack-of-fit test, docs/velocity.md), not only its coefficients: otherwise it is split, down to
  /// min_window_samples. Where a window still fails there and its residual is clearly above the
  /// noise, the adaptive curve follows the samples with a local interpolant (LocalRun). false
  /// judges by the coefficients alone (compression does: on nearly
  /// noise-free ground truth the residual test asks for windows that store more than the samples).
  bool lack_of_fit = true;
  /// Where windows were split for missed motion (CurveWindow::missed_motion) or spend a coefficient
  /// on fewer samples than the widest candidate spans (53; not the end windows), a local
  /// polynomial regression per coordinate takes over the rate when its velocity error,
  /// estimated against a low-bias pilot, is below the windows' (docs/velocity.md, "Local
  /// regression"). Needs `lack_of_fit` and an adaptive fit. The angular fit turns it off: the
  /// charts' noise varies along them, and the choice relies on one σ.
  bool local_regression = true;
  /// Threads for the fit where its work splits into independent parts (its windows, its two ends,
  /// the noise estimate's orders, the jump search's passes; from 2,000 samples) and for
  /// Curve::EvaluateMany; 0 = as many as the machine has, at most 256. The curve is the same for
  /// any number, and so is the error of a fit that fails: each part computes what it would on one
  /// thread, and the parts are put in order.
  int threads = 0;
  /// Told "fitting windows" with the samples fitted so far, as windows are accepted (may be empty;
  /// called from the fitting threads, one call at a time).
  ProgressFn progress;

  /// Throws OptionError naming the first field out of range: fixed_degree < 0 (with kFixed),
  /// window_s not positive and finite, max_conditioning <= 0, max_degree < 1,
  /// min_window_samples < 2, overlap outside [0, 1], gap_factor <= 1, min_gap_s < 0, noise_sigma
  /// negative or not finite, end_degree < 0, threads outside 0..256.
  void Validate() const;
};

/// Why a window was accepted.
enum class WindowVerdict {
  /// Its series reached the noise plateau (standardChop or a noise-like tail), or its halves
  /// predict held-out samples no better than it does (cross-validated fits, when the coefficients
  /// cannot tell), and its residual is consistent with the noise (the lack-of-fit test,
  /// docs/velocity.md).
  kResolved,
  /// It fails one of those tests but could not be split further (too few samples, or a literal
  /// fit: window_s, single_window, end windows): its velocity may miss motion there.
  kUnresolved,
  /// A fixed degree was asked for: nothing was tested for acceptance.
  kFixedDegree,
  /// A fit across a gap that stands in for a segment's end (docs/velocity.md, "Gaps"): its
  /// residual over the samples on both sides is consistent with the noise, and where it takes over
  /// its rate has the smaller variance and its residuals no trend.
  kBridge,
};

/// "resolved", "unresolved", "fixed_degree" or "bridge" (the JSON and the report name verdicts so).
std::string_view ToString(WindowVerdict verdict);

/// A window's residual is consistent with the noise while every coordinate's lack_of_fit score
/// stays at or below this (docs/velocity.md, "Residual test").
inline constexpr double kLackOfFitLimit = 3.0;

/// CurveWindow::reproduces_samples asks for at least this many residual degrees of freedom: a
/// window with fewer could match its samples to rounding with any motion between them.
inline constexpr Eigen::Index kExactResidualDof = 3;

/// One window: its core [core_begin, core_end] (seconds from the curve's origin), the samples used
/// and the fit, with a degree per coordinate (coefficients of lower-degree coordinates are padded
/// with zeros).
struct CurveWindow {
  double core_begin = 0, core_end = 0;
  double fit_begin = 0, fit_end = 0;
  Eigen::Index samples = 0;
  std::vector<int> degrees;
  ChebyshevSeries series;
  /// Coefficients of d/dx and d²/dx² of `series` (x the window's unit variable).
  Eigen::MatrixXd first_derivative, second_derivative;
  /// |c_k| per coordinate of the high-degree fit the degree was chosen from (diagnostics), (K x d).
  Eigen::MatrixXd coefficient_magnitudes;
  /// Root mean square of the residuals of the window's samples, per coordinate (diagnostics).
  Eigen::VectorXd residual_rms;
  /// The lack-of-fit statistic per coordinate: the residual sum of squares over σ² is χ² with
  /// m − N − 1 degrees of freedom for a fit that has resolved the motion; this is its standard
  /// normal score (Wilson–Hilferty), accepted up to kLackOfFitLimit (diagnostics).
  Eigen::VectorXd lack_of_fit;
  /// The noise σ per coordinate the residual was tested against: the noise profile's over the
  /// window's samples (Curve::noisier_samples), floored at the values' rounding level (diagnostics).
  Eigen::VectorXd noise_sigma;
  /// Its residual is at its values' rounding level in every coordinate (the floor of
  /// `noise_sigma`), with at least kExactResidualDof residual degrees of freedom to spare: the
  /// window reproduces its samples, whatever its coefficients say (exact data at a low rate leave
  /// unresolved windows of this kind; diagnostics).
  bool reproduces_samples = false;
  WindowVerdict verdict = WindowVerdict::kResolved;
  /// The window is a piece of a larger one that was split because it missed motion (its residual
  /// failed the lack-of-fit test, or its halves predicted held-out samples better).
  bool missed_motion = false;
};

/// A gap-free stretch of data with its windows, ordered in time.
struct CurveSegment {
  double begin = 0, end = 0;  ///< first and last sample time (s from origin)
  std::vector<CurveWindow> windows;
  /// The next segment follows without a gap: the data were split at a jump (CurveOptions::robust),
  /// and a time between the two segments belongs to the nearer one.
  bool continues = false;
};

/// Where the fit could not resolve the motion, the samples themselves: a cubic Hermite interpolant
/// through their values with the local rates of docs/velocity.md ("Local interpolant"). The first
/// and last sample carry the windows' own value and derivative unless they are a segment's end
/// (the curve stays C¹ where it passes from the fit to the samples).
struct LocalRun {
  std::vector<double> times;  ///< s from the curve's origin, increasing
  Eigen::MatrixXd values;     ///< (k x d), the curve's values without its steps
  Eigen::MatrixXd rates;      ///< (k x d), per second
  /// The values and rates come from a local polynomial regression (CurveOptions::local_regression)
  /// in the coordinates it replaced, not from the samples' own interpolant.
  bool regression = false;
};

/// The fitted curve.
class Curve {
 public:
  /// Value, first and second derivative (per second) at `stamp_ns`. Throws ComputeError when the
  /// time lies outside every segment by more than `tolerance_s` (e.g. inside a gap).
  void Evaluate(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::VectorXd> derivative,
                Eigen::Ref<Eigen::VectorXd> second_derivative, double tolerance_s = 0.0) const;

  /// Value only (cheaper), as Evaluate.
  void EvaluateValue(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, double tolerance_s = 0.0) const;
  /// Value and first derivative, as Evaluate.
  void EvaluateVelocity(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::VectorXd> derivative,
                        double tolerance_s = 0.0) const;

  /// Whether the curve is defined at `stamp_ns`: within a segment by `tolerance_s`, or between two
  /// segments split at a jump (not before the first sample, after the last, or inside a gap). Where
  /// it is not, Evaluate and EvaluateMany throw.
  bool Covers(int64_t stamp_ns, double tolerance_s = 0.0) const;

  /// Values (n x d) and, for order >= 1 and 2, first and second derivatives (n x d) at many stamps
  /// (any order; row i belongs to stamps_ns[i]). The point-wise calls' numbers to rounding (where
  /// the CPU fuses multiply-adds, the vectorised evaluation does), several times faster: the
  /// queries a window serves are evaluated together by vectorised Clenshaw, and many queries are
  /// split over the threads the curve was fitted with (CurveOptions::threads; all cores for a
  /// curve from FromParts). Each query's numbers do not depend on that split.
  void EvaluateMany(std::span<const int64_t> stamps_ns, int order, Eigen::MatrixXd* values,
                    Eigen::MatrixXd* first = nullptr, Eigen::MatrixXd* second = nullptr,
                    double tolerance_s = 0.0) const;

  /// Rebuilds a curve from its parts, e.g. a stored model read back: each window needs its core,
  /// fit interval, degrees and series (its derivative coefficients are recomputed). Windows must
  /// be in time order with cores that tile their segment. Throws std::invalid_argument otherwise.
  static Curve FromParts(int64_t origin_ns, std::vector<CurveSegment> segments, Eigen::VectorXd noise_sigma,
                         Eigen::VectorXd residual_rms);

  int64_t origin_ns() const { return origin_ns_; }
  int dimension() const { return dimension_; }
  const std::vector<CurveSegment>& segments() const { return segments_; }
  /// The noise σ per coordinate used to choose degrees (estimated or given): the recording's level.
  const Eigen::VectorXd& noise_sigma() const { return noise_sigma_; }
  /// Where stretches of the samples are clearly noisier than that level (or than the stamp noise's
  /// σ, stamp_noise_s), the windows there were tested against their own (docs/velocity.md, "Noise
  /// profile"): how many samples, and the largest σ per coordinate of the profile (noise_sigma where
  /// it is the level throughout, never below it).
  Eigen::Index noisier_samples() const { return noisier_samples_; }
  const Eigen::VectorXd& noise_sigma_max() const { return noise_sigma_max_.size() > 0 ? noise_sigma_max_ : noise_sigma_; }
  /// Where the samples scatter in proportion to their rate, as stamps off by white errors make them
  /// (docs/velocity.md, "Stamp noise"): the RMS of those errors in seconds, and the windows were
  /// tested against that noise; 0 where no such scatter was found (or noise_sigma was given).
  double stamp_noise_s() const { return stamp_noise_s_; }
  /// Per coordinate, the step q the values were rounded to, 0 where they were not (docs/velocity.md,
  /// "Rounded positions"). Where they were rounded to it (IsRounded), an estimated noise σ is at
  /// least the rounding's: q/sqrt(12), and sqrt(q²/12 + σ_n²) where the mean square of their
  /// differences shows noise σ_n added before the rounding.
  const Eigen::VectorXd& resolution() const { return resolution_; }
  /// Whether coordinate c's estimated noise σ is the rounding's: its values were rounded, and the
  /// median of their differences reads less noise than the rounding makes (a staircase, or a median
  /// of 4th differences that is itself a whole number of steps).
  bool AtRounding(Eigen::Index c) const;
  /// Per coordinate, whether its values were rounded to a step they moved less than a sample at a
  /// time (a staircase), and were fitted placed between their steps: on a curve through the
  /// instants they pass from one step to the next, each within its own step (docs/velocity.md,
  /// "Rounded positions"). Its noise σ is then at least how well those crossings predict each
  /// other, not the step's q/sqrt(12).
  const std::vector<bool>& staircase() const { return staircase_; }
  /// Root mean square of the fit residuals over the samples fitted (outliers left out), per coordinate.
  const Eigen::VectorXd& residual_rms() const { return residual_rms_; }
  /// Total number of stored values (Σ over windows of (degree + 1) per coordinate).
  Eigen::Index stored_values() const;
  /// Times (s from the origin) of the samples left out as outliers, and of the jumps the data were
  /// split at (midway between the two samples), CurveOptions::robust.
  const std::vector<double>& outlier_times() const { return outlier_times_; }
  const std::vector<double>& jump_times() const { return jump_times_; }
  /// Times (s from the origin, midway between the two samples) of the steps of the values taken
  /// out before fitting (CurveOptions::robust); the curve's values include them, its derivatives
  /// do not.
  const std::vector<double>& step_times() const { return step_times_; }
  /// The windows that were accepted unresolved (WindowVerdict::kUnresolved).
  Eigen::Index unresolved_windows() const;
  /// Where the curve follows the samples instead of the windows (CurveOptions::lack_of_fit), in
  /// time order; empty when every window resolved the motion.
  const std::vector<LocalRun>& local_runs() const { return local_runs_; }
  /// The samples in local_runs of the samples' own interpolant (each run's ends included).
  Eigen::Index local_samples() const;
  /// The samples in local_runs of the local polynomial regression (each run's ends included).
  Eigen::Index regression_samples() const;

 private:
  // Where a time falls: its window, and when it is in a blending zone the next window with the
  // blend weight s of the right one and its derivatives per second.
  struct Placement {
    const CurveWindow* left = nullptr;
    const CurveWindow* right = nullptr;
    double s = 0, ds = 0, dds = 0;
  };
  Placement Locate(double t, double tolerance_s) const;
  // The segment holding t (Covers), nullptr where none does.
  const CurveSegment* FindSegment(double t, double tolerance_s) const;
  void EvaluateUpTo(int64_t stamp_ns, int order, Eigen::Ref<Eigen::VectorXd> value,
                    Eigen::Ref<Eigen::VectorXd>* derivative, Eigen::Ref<Eigen::VectorXd>* second_derivative,
                    double tolerance_s) const;
  friend Curve FitCurve(std::span<const int64_t>, const Eigen::Ref<const Eigen::MatrixXd>&, const CurveOptions&);
  int64_t origin_ns_ = 0;
  int dimension_ = 0;
  int threads_ = 0;  // CurveOptions::threads, for EvaluateMany
  std::vector<CurveSegment> segments_;
  Eigen::VectorXd noise_sigma_;
  Eigen::Index noisier_samples_ = 0;
  Eigen::VectorXd noise_sigma_max_;  // empty: noise_sigma_
  double stamp_noise_s_ = 0.0;
  Eigen::VectorXd resolution_;  // per coordinate, 0: not rounded
  Eigen::VectorXd rounding_;    // per coordinate, the rounding's σ flooring an estimate, 0: none (or placed)
  std::vector<bool> staircase_;  // per coordinate, placed between its steps
  Eigen::VectorXd residual_rms_;
  std::vector<double> outlier_times_, jump_times_, step_times_;
  // Row k: the sum of the first k + 1 steps, added to values after step_times_[k].
  Eigen::MatrixXd step_offsets_;
  // How many steps lie before time t (row StepsBefore(t) - 1 of step_offsets_ is their sum).
  Eigen::Index StepsBefore(double t) const;
  // Adds the steps before time t to a value.
  template <typename Row>
  void AddSteps(double t, Row&& value) const;
  std::vector<LocalRun> local_runs_;
  // The local run holding time t, or nullptr.
  const LocalRun* LocalRunAt(double t) const;
};

/// Quintic smoothstep s(u) = 6u⁵ − 15u⁴ + 10u³ on u clamped to [0, 1], with ds/du and d²s/du²:
/// the C² blending weight of overlapping fits.
void Smoothstep(double u, double* s, double* ds, double* dds);

/// The step q of the lattice `values` were rounded to (docs/velocity.md, "Rounded positions"):
/// every difference between consecutive values is a whole multiple of q, to the rounding of
/// doubles read from decimals, and q stands well above that rounding; 0 where there is no such
/// lattice (values not rounded, a lattice too fine to be told, a coordinate that hardly moves, a
/// value that is not finite). Rounding to q is noise of σ q/sqrt(12) at least: white where the
/// motion crosses many steps between samples, a staircase where it does not, and there the
/// differences read no noise at all.
double FindResolution(const Eigen::Ref<const Eigen::VectorXd>& values);

/// Whether `values` on a lattice of step `q` (FindResolution) were rounded to it rather than lying
/// on it by themselves: most runs of five consecutive values that change have a nonzero 4th
/// difference. Rounding scatters the values off any cubic (a staircase's single steps where the
/// motion is slower than a step a sample, white rounding noise where it is faster); motion that
/// lies on the lattice by itself (a simulator's constant velocity of whole steps a sample, stops
/// and starts) is a polynomial between its corners, and its values are exact.
bool IsRounded(const Eigen::Ref<const Eigen::VectorXd>& values, double q);

/// Fits `values` (m x d, d <= 4; row i sampled at stamps_ns[i]) with a Curve. Stamps need not be
/// sorted or unique (samples are sorted by stamp; equal stamps are averaged by the least squares).
/// Throws OptionError for bad options (CurveOptions::Validate); ComputeError for fewer than 2
/// samples, all-equal stamps, or a fixed degree above what a window's samples support.
Curve FitCurve(std::span<const int64_t> stamps_ns, const Eigen::Ref<const Eigen::MatrixXd>& values,
               const CurveOptions& options = {});

}  // namespace cheval::cheb

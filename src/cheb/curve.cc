#include "cheval/cheb/curve.h"

#include "bridges.h"
#include "conditioning.h"
#include "end_caps.h"
#include "jumps.h"
#include "local_rates.h"
#include "local_regression.h"
#include "noise_profile.h"
#include "residual_test.h"
#include "staircase.h"
#include "work_queue.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>
#include <numeric>
#include <tuple>

#include <fmt/format.h>

#include "cheval/cheb/degree.h"
#include "cheval/common/error.h"
#include "cheval/common/options.h"

namespace cheval::cheb {
namespace {

// The relative tolerance below which coefficients are rounding, not signal: the chop's floor when
// the data are noise-free.
constexpr double kRoundingTolerance = 1e-13;
// The noise level, a scale of the recording's differences, scatters like a variance estimate with
// about one degree of freedom per kSamplesPerNoiseDof samples where it is their median (measured on
// white noise: 0.16–0.22 per sample from 100 to 1,000 samples), and per kSamplesPerWinsorizedDof
// where it is Huber's winsorized scale, below DifferenceMagnitudes::kWinsorizedBelow samples
// (0.32–0.35 per sample from 30 to 1,000). Where that is fewer than kMarginDof, the level scatters
// by more than the 10 % that kNoiseMargin absorbs (a relative standard deviation of 1/sqrt(2k)),
// and a level read low would make the residual test raise degrees to fit the noise.
constexpr double kSamplesPerNoiseDof = 6.0;
constexpr double kSamplesPerWinsorizedDof = 3.0;
constexpr double kMarginDof = 50.0;
// A window that passes the lack-of-fit test with a score above this (2 standard deviations, where
// noise consistent with the 1.1σ margin rarely comes) is compared with its halves
// (SplitPredictsBetter). At 1 the charts of rotations, whose noise varies along them, were split
// where that did not help (docs/decisions.md).
constexpr double kSplitScore = 2.0;
// Held-out squared errors come from sums (Σz² − 2cᵀb + cᵀGc of samples centred on their mean):
// below this fraction of Σ(z − z̄)² they are rounding (nearly exact data), and comparing a window
// with its halves by them says nothing.
constexpr double kHeldOutFloor = 1e-12;
// An undecided window whose cross-validation wanted no more degrees (SplitPredictsBetter) is split
// only when its halves predict better by this many standard deviations of the comparison's scatter
// where the window is right: a ratio near 1 is a coin flip, and halving again on one down to the
// smallest windows multiplies the velocity's variance (a 0.5 s clip under 2 mm: ratios of
// 0.96–0.99 cut 51 samples into four of 16–19).
constexpr double kSplitMargin = 2.0;
// An end step (from the interval's end to the second sample from it) of more than this many mean
// steps is a hole at the end of a window, which lowers its top degree (WindowFitter::TopDegree).
constexpr double kEndHoleRatio = 2.5;
// A fit of at least this many samples takes CurveOptions::threads threads where its work splits
// into independent parts; below, one (starting a thread costs about as much as fitting a few
// hundred samples).
constexpr Eigen::Index kParallelSamples = 2000;
// Curve::EvaluateMany splits at least this many queries over the curve's threads.
constexpr Eigen::Index kParallelQueries = 8192;
// Curve::EvaluateMany's queries per block of scratch.
constexpr Eigen::Index kEvaluationBlock = 4096;
// End windows are halved (RefineEnds) while they keep this many samples on each side.
constexpr Eigen::Index kMinEndWindowSamples = 24;
using internal::kLackOfFitLimit;
using internal::kMaxGramCondition;
using internal::kNoiseMargin;
using internal::LackOfFitScore;
using internal::WindowSigma;

// Fits one window and, for automatic degrees, says whether it should be split instead.
class WindowFitter {
 public:
  WindowFitter(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const internal::NoiseProfile& noise,
               const CurveOptions& options, const Eigen::VectorXd& rounding, double level_dof)
      : t_(t), z_(z), noise_(noise), options_(options), rounding_(rounding), level_dof_(level_dof) {}

  // Fits the window of core [a, b] inside segment [segment_begin, segment_end]. Returns nullopt
  // when the series is not resolved and splitting is allowed.
  // With `held_out`, a cross-validated window also gives its held-out squared error per sample and
  // coordinate at its cross-validated degrees (empty for the other methods). With `undecided`, a
  // window that may be split but whose coefficients cannot show it resolved while its residual is
  // consistent with the noise is returned (verdict resolved) with *undecided set: the caller
  // decides by prediction whether to split it (SplitPredictsBetter).
  // With `missed`, a window that is not returned because its residual fails the lack-of-fit test
  // sets *missed (it missed motion). With `reusable`, a window fitted without may_split tells
  // whether the same call with may_split would return it unchanged (no subsample probe, no degree
  // lowered for conditioning, coefficients and residual both resolved).
  std::optional<CurveWindow> Fit(double a, double b, double segment_begin, double segment_end, bool may_split,
                                 Eigen::VectorXd* held_out = nullptr, bool* undecided = nullptr,
                                 bool* missed = nullptr, bool* reusable = nullptr) const {
    if (reusable != nullptr) *reusable = false;
    const Span span = Samples(a, b, segment_begin, segment_end);
    CurveWindow window;
    window.core_begin = a;
    window.core_end = b;
    window.fit_begin = span.interval.a;
    window.fit_end = span.interval.b;
    const Eigen::Index m = span.count, distinct = span.distinct;
    window.samples = m;
    const Interval interval = span.interval;
    if (distinct < 2 || !(interval.b > interval.a)) {
      throw ComputeError(fmt::format("cannot fit a window at {:.6f} s..{:.6f} s: it has {} distinct stamps",
                                     window.fit_begin, window.fit_end, distinct));
    }
    const auto tw = t_.segment(span.first, m);
    const auto zw = z_.middleRows(span.first, m);
    const int d = static_cast<int>(z_.cols());
    window.degrees.assign(d, 0);

    if (options_.degree_method == DegreeMethod::kFixed) {
      if (options_.fixed_degree + 1 > distinct) {
        throw ComputeError(fmt::format(
            "degree {} needs at least {} distinct stamps per window, but the window {:.6f} s..{:.6f} s has {}; "
            "use a smaller CurveOptions::fixed_degree or a longer window_s",
            options_.fixed_degree, options_.fixed_degree + 1, window.fit_begin, window.fit_end, distinct));
      }
      std::fill(window.degrees.begin(), window.degrees.end(), options_.fixed_degree);
      window.series = FitLeastSquares(tw, zw, options_.fixed_degree, interval);
      window.coefficient_magnitudes = window.series.coefficients.cwiseAbs();
      Eigen::VectorXd floor;
      const Eigen::VectorXd sigma = WindowSigma(noise_.Over(span.first, m), zw, &floor);
      LackOfFit(tw, zw, sigma, floor, &window);
      window.verdict = WindowVerdict::kFixedDegree;
      Finish(&window);
      return window;
    }

    int top = TopDegree(span);
    // A window far longer than its top degree needs (m > top², e.g. the whole of an hour-long
    // recording) is usually split: a subsample with N²/m = 2 (well conditioned, coefficient noise
    // still white) tells that at a fraction of the cost. Only its "unresolved" is trusted: a
    // subsample's noise plateau is higher, so it resolves no less than all the samples would.
    const Eigen::VectorXd level = noise_.Over(span.first, m);
    const Eigen::Index stride = SubsampleStride(m, top);
    if (may_split && stride >= 2 && !ResolvedOnSubsample(tw, zw, level, stride, top, interval)) return std::nullopt;
    bool lowered = false;
    // Cross-validation needs the normal equations of each fold; their sum is the whole window's,
    // so the samples are visited once either way.
    const bool cross_validate = options_.degree_method == DegreeMethod::kCrossValidation;
    std::optional<Folds> folds;
    NormalEquations probe;
    if (cross_validate) {
      folds = BuildFolds(tw, zw, top, interval);
      probe = folds->Uncentred();
    } else {
      probe = BuildNormalEquations(tw, zw, top, interval);
    }
    // The probe fit at the top degree; uneven sampling can make it ill-conditioned: then split the
    // window if allowed, else lower the degree until it is well posed. One factorisation serves
    // every degree up to top (leading blocks).
    std::optional<NestedCholesky> cholesky;
    while (true) {
      double condition = std::numeric_limits<double>::infinity();
      try {
        cholesky.emplace(probe, top);
        condition = cholesky->Condition(top);
      } catch (const ComputeError&) {
        cholesky.reset();
      }
      if (condition <= kMaxGramCondition) break;
      if (may_split) return std::nullopt;
      if (top <= 1) {
        throw ComputeError(fmt::format("cannot fit the window {:.6f} s..{:.6f} s: its {} samples do not determine "
                                       "even a line",
                                       window.fit_begin, window.fit_end, m));
      }
      top = std::max(1, static_cast<int>(0.7 * top));  // a leading block of the same normal equations
      lowered = true;
    }
    const Eigen::MatrixXd high = cholesky->Solve(top, probe.rhs);
    window.coefficient_magnitudes = high.cwiseAbs();
    // standardChop decides whether the window resolves the motion (its coefficients reach the noise
    // plateau); it also picks the degree for kChop. Cross-validation picks the degree of a resolved
    // window for kCrossValidation: held-out error alone cannot tell an unresolved window (every
    // candidate underfits) from a resolved one.
    bool resolved = ChopDegrees(high, m, level, &window.degrees);
    // The chop looks for a plateau by shape, which a short noisy window can hide: when the top third
    // of the coefficients is statistically pure noise, the window is resolved anyway.
    Eigen::VectorXd floor;
    const Eigen::VectorXd sigma = WindowSigma(level, zw, &floor);
    if (!resolved) resolved = TailIsNoise(high, *cholesky, sigma);
    if (held_out != nullptr) held_out->resize(0);
    // No plateau and a tail above the noise say that the window *may* miss motion above its top
    // degree, not that it does: at 2 mm of noise a 190-sample window of a legged gait has such a
    // tail, and so do all its halves down to the smallest, whose cross-validated degrees (2–3) then
    // miss more than the whole did. When the residual is consistent with the noise, prediction
    // decides instead (the caller's SplitPredictsBetter), unless the held-out errors are rounding.
    bool arbitrate = !resolved && may_split && undecided != nullptr && cross_validate && options_.lack_of_fit;
    if (cross_validate && (resolved || !may_split || arbitrate)) {
      Eigen::VectorXd error;
      window.degrees = CrossValidatedDegrees(*folds, top, SearchReach(window.degrees, top), &error);
      if (held_out != nullptr) *held_out = error / static_cast<double>(m);
      if (arbitrate) {
        Eigen::RowVectorXd spread = Eigen::RowVectorXd::Zero(d);
        for (const Eigen::RowVectorXd& squares : folds->squares) spread += squares;
        for (int c = 0; c < d; ++c) arbitrate = arbitrate && error[c] > kHeldOutFloor * spread[c];
      }
    }
    if (!resolved && !arbitrate && may_split) return std::nullopt;

    // The residual must be consistent with the noise too: a series can look resolved while the
    // motion it misses lies above the top degree the window may use. A coordinate whose residual
    // fails at the chosen degree takes the lowest degree of the grid that passes, if any. In a
    // short recording the noise level is itself uncertain (level_dof_), and a level read low
    // would raise the degree to fit the noise: the raise tests against F instead of χ² there.
    window.series.interval = interval;
    SetDegrees(*cholesky, probe, &window);
    bool consistent = LackOfFit(tw, zw, sigma, floor, &window) || !options_.lack_of_fit;
    if (!consistent) {
      const Centred centred = Centre(probe, zw);
      bool raised = false;
      for (int c = 0; c < d; ++c) {
        if (window.lack_of_fit[c] <= kLackOfFitLimit) continue;
        for (const int degree : DegreeGrid(top)) {
          if (degree <= window.degrees[c]) continue;
          if (centred.LackOfFit(*cholesky, degree, c, m, sigma[c], level_dof_) <= kLackOfFitLimit || degree == top) {
            window.degrees[c] = degree;
            raised = true;
            break;
          }
        }
      }
      if (raised) {
        SetDegrees(*cholesky, probe, &window);
        consistent = LackOfFit(tw, zw, sigma, floor, &window);
      }
    }
    if (!consistent && may_split) {
      if (missed != nullptr) *missed = true;
      return std::nullopt;
    }
    LowerBelowRounding(tw, zw, sigma, floor, *cholesky, probe, &window);
    if (arbitrate) *undecided = true;
    if (reusable != nullptr) *reusable = !may_split && stride < 2 && !lowered && resolved && consistent;
    window.verdict = (resolved || arbitrate) && consistent ? WindowVerdict::kResolved : WindowVerdict::kUnresolved;
    Finish(&window);
    return window;
  }

  // Whether the window of core [a, b] resolves the motion at its top degree (Fit's probe, the
  // subsample's too) with a residual there clearly consistent with the noise: a lack-of-fit score
  // of at most kSplitScore in every coordinate. Fit may split a window that does not for missed
  // motion, which marks its pieces (CurveWindow::missed_motion); FitCore cuts an end window
  // unfitted only when it passes. `subsample_unresolved` is set when the subsample probe fails:
  // Fit with may_split then returns nullopt for the same window at once (the same probe), with
  // nothing marked.
  bool ResolvedAtTop(double a, double b, double segment_begin, double segment_end,
                     bool* subsample_unresolved = nullptr) const {
    const Span span = Samples(a, b, segment_begin, segment_end);
    if (span.distinct < 2 || !(span.interval.b > span.interval.a)) return false;
    const int top = TopDegree(span);
    const auto tw = t_.segment(span.first, span.count);
    const auto zw = z_.middleRows(span.first, span.count);
    const Eigen::VectorXd level = noise_.Over(span.first, span.count);
    const Eigen::Index stride = SubsampleStride(span.count, top);
    if (stride >= 2 && !ResolvedOnSubsample(tw, zw, level, stride, top, span.interval)) {
      if (subsample_unresolved != nullptr) *subsample_unresolved = true;
      return false;
    }
    const NormalEquations normal = BuildNormalEquations(tw, zw, top, span.interval);
    try {
      const NestedCholesky cholesky(normal, top);
      if (!(cholesky.Condition(top) <= kMaxGramCondition)) return false;
      const Eigen::MatrixXd high = cholesky.Solve(top, normal.rhs);
      std::vector<int> degrees(static_cast<size_t>(zw.cols()));
      const Eigen::VectorXd sigma = WindowSigma(level, zw);
      if (!ChopDegrees(high, span.count, level, &degrees) && !TailIsNoise(high, cholesky, sigma)) return false;
      const Centred centred = Centre(normal, zw);
      for (Eigen::Index c = 0; c < zw.cols(); ++c) {
        if (!(centred.LackOfFit(cholesky, top, c, span.count, sigma[c]) <= kSplitScore)) return false;
      }
      return true;
    } catch (const ComputeError&) {
      return false;
    }
  }

  // Whether the cross-validated degree of the window of core [a, b] certainly exceeds `degree` in
  // some coordinate, told without the full search: the held-out errors of the search's grid up to
  // three steps above `degree` (normal equations of that degree only), where some degree above it
  // predicts better than every degree up to it, so the full search's minimum lies above it too.
  // False when that cannot be told (a short window, held-out errors at the rounding level). The
  // lack-of-fit test only raises degrees, so a window fitted in full would exceed it as well.
  bool DegreeCertainlyAbove(double a, double b, double segment_begin, double segment_end, int degree) const {
    const Span span = Samples(a, b, segment_begin, segment_end);
    if (span.distinct < 2 || !(span.interval.b > span.interval.a)) return false;
    const std::vector<int> full = DegreeGrid(TopDegree(span));
    const auto above = std::upper_bound(full.begin(), full.end(), degree);
    if (above == full.end()) return false;
    const int reach = *std::min(above + 2, full.end() - 1);
    const Folds folds = BuildFolds(t_.segment(span.first, span.count), z_.middleRows(span.first, span.count), reach,
                                   span.interval);
    const std::vector<int> grid = DegreeGrid(reach);
    const Eigen::MatrixXd error = HeldOutErrors(folds, grid, reach);
    for (Eigen::Index c = 0; c < error.cols(); ++c) {
      double low = std::numeric_limits<double>::infinity(), high = low, spread = 0.0;
      for (size_t g = 0; g < grid.size(); ++g) {
        double& best = grid[g] <= degree ? low : high;
        best = std::min(best, error(static_cast<Eigen::Index>(g), c));
      }
      for (const Eigen::RowVectorXd& squares : folds.squares) spread += squares[c];
      // A margin far above the rounding of the two searches' sums, which may differ in the last bits.
      if (high > kHeldOutFloor * spread && high < (1.0 - 1e-9) * low) return true;
    }
    return false;
  }

  // Residuals of a window's series at its samples, tested against σ: fills residual_rms,
  // lack_of_fit and reproduces_samples (`floor`: the samples' rounding level, WindowSigma); whether
  // every coordinate passes.
  bool LackOfFit(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                 const Eigen::VectorXd& sigma, const Eigen::VectorXd& floor, CurveWindow* window) const {
    const Eigen::Index m = t.size(), d = z.cols();
    Eigen::VectorXd x(m);
    for (Eigen::Index i = 0; i < m; ++i) x[i] = window->series.interval.ToUnit(t[i]);
    const Eigen::MatrixXd residual = z - EvaluateSeries(window->series.coefficients, x);
    window->noise_sigma = sigma;
    window->residual_rms.resize(d);
    window->lack_of_fit.resize(d);
    window->reproduces_samples = d > 0;
    bool passes = true;
    for (Eigen::Index c = 0; c < d; ++c) {
      const double rss = residual.col(c).squaredNorm();
      const Eigen::Index dof = m - window->degrees[c] - 1;
      window->residual_rms[c] = std::sqrt(rss / static_cast<double>(m));
      window->lack_of_fit[c] = LackOfFitScore(rss, sigma[c], dof);
      window->reproduces_samples = window->reproduces_samples && dof >= kExactResidualDof &&
                                   window->residual_rms[c] <= floor[c];
      passes = passes && window->lack_of_fit[c] <= kLackOfFitLimit;
    }
    return passes;
  }

  // Values rounded to a lattice (Curve::resolution) whose differences read less noise than the
  // rounding's q/sqrt(12) (a staircase, or a median of whole-step differences read low) may have
  // errors correlated over many samples, and cross-validation follows them. A coordinate tested
  // against that rounding level whose residual lies clearly below it takes the highest lower
  // degree of the grid whose residual does not.
  void LowerBelowRounding(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                          const Eigen::VectorXd& sigma, const Eigen::VectorXd& floor, const NestedCholesky& cholesky,
                          const NormalEquations& probe, CurveWindow* window) const {
    const Eigen::Index m = t.size();
    bool lowered = false;
    std::optional<Centred> centred;
    for (Eigen::Index c = 0; c < z.cols(); ++c) {
      if (!internal::AtRoundingLevel(sigma[c], rounding_[c])) continue;
      // A plain two-sided χ² test: the margin on σ (kNoiseMargin) guards only the upper side.
      const double unmargined = sigma[c] / kNoiseMargin;
      auto score = [&](int degree) {
        if (!centred) centred = Centre(probe, z);
        return centred->LackOfFit(cholesky, degree, c, m, unmargined);
      };
      if (score(window->degrees[c]) >= -kLackOfFitLimit) continue;
      const std::vector<int> grid = DegreeGrid(window->degrees[c]);
      for (auto it = grid.rbegin(); it != grid.rend(); ++it) {
        if (*it >= window->degrees[c]) continue;
        window->degrees[c] = *it;
        lowered = true;
        if (score(*it) >= -kLackOfFitLimit) break;
      }
    }
    if (lowered) {
      SetDegrees(cholesky, probe, window);
      LackOfFit(t, z, sigma, floor, window);
    }
  }

  // The window's series at its per-coordinate degrees: leading blocks of one factorisation.
  static void SetDegrees(const NestedCholesky& cholesky, const NormalEquations& probe, CurveWindow* window) {
    const int degree = *std::max_element(window->degrees.begin(), window->degrees.end());
    const auto d = static_cast<int>(window->degrees.size());
    window->series.coefficients = Eigen::MatrixXd::Zero(degree + 1, d);
    for (int c = 0; c < d; ++c) {
      window->series.coefficients.col(c).head(window->degrees[c] + 1) =
          cholesky.Solve(window->degrees[c], probe.rhs.col(c));
    }
  }

  // The normal equations of the samples about their mean, whose residual sum of squares at any
  // degree is Σ(z − z̄)² − cᵀb without touching the samples (cancellation limits it to residuals
  // well above 1e-8 of the spread: used to search, the chosen degree is checked on the samples).
  struct Centred {
    Eigen::MatrixXd rhs;
    Eigen::RowVectorXd squares;
    double LackOfFit(const NestedCholesky& cholesky, int degree, Eigen::Index c, Eigen::Index m, double sigma,
                     double sigma_dof = 0.0) const {
      const Eigen::VectorXd coefficients = cholesky.Solve(degree, rhs.col(c));
      const double rss = std::max(0.0, squares[c] - coefficients.dot(rhs.col(c).head(degree + 1)));
      return LackOfFitScore(rss, sigma, m - degree - 1, sigma_dof);
    }
  };
  static Centred Centre(const NormalEquations& probe, const Eigen::Ref<const Eigen::MatrixXd>& z) {
    const Eigen::RowVectorXd mean = z.colwise().mean();
    // Σ T_k(x_i)(z_i − z̄) = b_k − z̄·Σ T_k(x_i), and Σ T_k(x_i) is column 0 of the normal matrix.
    return {probe.rhs - probe.gram.col(0) * mean, (z.rowwise() - mean).colwise().squaredNorm()};
  }

  // Whether the top third of a probe's coefficients ((top + 1) x d) is consistent with white noise
  // of the estimated σ in every coordinate: with σ_k = σ·sqrt((G⁻¹)_kk) the standard deviation of
  // coefficient k, Σ (c_k/σ_k)² over the n tail coefficients is χ²(n) for pure noise; the tail is
  // noise when it stays below n + 4·sqrt(2n) (about 4 standard deviations of χ²(n)). `sigma` is the
  // window's (WindowSigma: floored at the values' rounding level, which exact data's coefficients
  // reach). Needs a tail of at least 8 coefficients.
  static bool TailIsNoise(const Eigen::MatrixXd& high, const NestedCholesky& cholesky, const Eigen::VectorXd& sigma) {
    const Eigen::Index top = high.rows() - 1, n = (top + 1) / 3;
    if (n < 8) return false;
    const Eigen::Index first = top + 1 - n;
    const Eigen::VectorXd variance_factors =
        cholesky.VarianceFactors(static_cast<int>(top), static_cast<int>(first));
    const double limit = static_cast<double>(n) + 4.0 * std::sqrt(2.0 * static_cast<double>(n));
    for (Eigen::Index c = 0; c < high.cols(); ++c) {
      if (!(sigma[c] > 0.0)) return false;
      double chi2 = 0.0;
      for (Eigen::Index k = first; k <= top; ++k) {
        chi2 += high(k, c) * high(k, c) / (sigma[c] * sigma[c] * variance_factors[k - first]);
      }
      if (!(chi2 <= limit)) return false;
    }
    return true;
  }

  // Whether every `stride`-th sample resolves the window at degree `top` (true when that cannot
  // be told: an ill-conditioned subsample); `level` is the window's noise.
  bool ResolvedOnSubsample(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                           const Eigen::VectorXd& level, Eigen::Index stride, int top, const Interval& interval) const {
    const Eigen::Index count = (t.size() + stride - 1) / stride;
    Eigen::VectorXd st(count);
    Eigen::MatrixXd sz(count, z.cols());
    for (Eigen::Index i = 0; i < count; ++i) {
      st[i] = t[i * stride];
      sz.row(i) = z.row(i * stride);
    }
    const NormalEquations normal = BuildNormalEquationsUnchecked(st, sz, top, interval);
    try {
      const NestedCholesky cholesky(normal, top);
      if (!(cholesky.Condition(top) <= kMaxGramCondition)) return true;
      const Eigen::MatrixXd high = cholesky.Solve(top, normal.rhs);
      std::vector<int> degrees(static_cast<size_t>(z.cols()));
      return ChopDegrees(high, count, level, &degrees) || TailIsNoise(high, cholesky, WindowSigma(level, sz));
    } catch (const ComputeError&) {
      return true;
    }
  }

  // The candidate degrees of a search up to `top`: 2, then a factor 1.25 apart (rounded, distinct),
  // and top itself.
  static std::vector<int> DegreeGrid(int top) {
    std::vector<int> grid;
    for (double g = 2; g < top; g *= 1.25) {
      const int degree = static_cast<int>(std::lround(g));
      if (grid.empty() || degree != grid.back()) grid.push_back(degree);
    }
    grid.push_back(top);
    return grid;
  }

  // Derivative coefficients of a fitted window.
  static void Finish(CurveWindow* window) {
    window->first_derivative = DerivativeCoefficients(window->series.coefficients);
    window->second_derivative = DerivativeCoefficients(window->first_derivative);
  }

 private:
  // standardChop on each coordinate of a probe fit `high` ((top + 1) x d) of m samples whose noise
  // is `level`: the degree it keeps per coordinate, and whether every coordinate reached its noise
  // plateau (resolved).
  static bool ChopDegrees(const Eigen::MatrixXd& high, Eigen::Index m, const Eigen::VectorXd& level,
                          std::vector<int>* degrees) {
    const int top = static_cast<int>(high.rows()) - 1;
    bool resolved = true;
    for (Eigen::Index c = 0; c < high.cols(); ++c) {
      // The mean (c_0) says nothing about how well the motion is resolved, and a large offset
      // (positions far from the origin) would make every other coefficient look negligible:
      // the chop sees the series relative to the largest varying coefficient.
      Eigen::VectorXd coefficients = high.col(c);
      coefficients[0] = top >= 1 ? coefficients.tail(top).cwiseAbs().maxCoeff() : 0.0;
      const double scale = coefficients.cwiseAbs().maxCoeff();
      (*degrees)[c] = 0;
      if (scale == 0.0) continue;  // a constant coordinate: degree 0
      // Noise level of a coefficient of m equispaced samples: σ·sqrt(2/m) (docs/velocity.md, "Formulas").
      const double noise = level[c] * std::sqrt(2.0 / static_cast<double>(m));
      const double tol = std::clamp(noise / scale, kRoundingTolerance, 0.5);
      const int keep = StandardChop(coefficients, tol);
      // StandardChop needs 17 coefficients; below that, or without a plateau, it keeps all.
      if (keep == top + 1) resolved = false;
      (*degrees)[c] = keep - 1;
    }
    return resolved;
  }

  // The samples a window of core [a, b] is fitted to: its core extended by the overlap on each
  // side, within its segment.
  struct Span {
    Interval interval;
    Eigen::Index first = 0, count = 0, distinct = 0;
    // The longest step between consecutive samples, and the longer of the distances from each end
    // of the interval to the second sample from it.
    double largest_step = 0.0, end_step = 0.0;
  };
  Span Samples(double a, double b, double segment_begin, double segment_end) const {
    const double extension = options_.overlap * (b - a);
    Span span;
    span.interval = {std::max(a - extension, segment_begin), std::min(b + extension, segment_end)};
    span.first = std::lower_bound(t_.data(), t_.data() + t_.size(), span.interval.a) - t_.data();
    const Eigen::Index last = std::upper_bound(t_.data(), t_.data() + t_.size(), span.interval.b) - t_.data();
    span.count = last - span.first;
    span.distinct = span.count > 0 ? 1 : 0;
    for (Eigen::Index i = span.first + 1; i < last; ++i) {
      span.distinct += t_[i] != t_[i - 1] ? 1 : 0;
      span.largest_step = std::max(span.largest_step, t_[i] - t_[i - 1]);
    }
    if (span.count >= 2) {
      span.end_step = std::max(t_[span.first + 1] - span.interval.a, span.interval.b - t_[last - 2]);
    }
    return span;
  }

  // The stride of Fit's subsample probe of m samples at degree top (below 2: none).
  static Eigen::Index SubsampleStride(Eigen::Index m, int top) {
    return m / std::max<Eigen::Index>(Eigen::Index{top} * top / 2, 16 * (top + 1));
  }

  // The highest degree a window may use: max_degree, N²/m ≤ max_conditioning, distinct stamps − 1,
  // and what its holes allow. A polynomial of degree N is pinned down where its samples are closer
  // than its own resolution: π/(2N) of the interval inside it (the spacing of Chebyshev points
  // there), about the interval over N² at its ends (where N²/m ≤ max_conditioning comes from, for
  // even spacing). Across a longer hole it is free to swing, and its rate at the samples beside the
  // hole with it: on TUM fr2/desk's ground truth (300 Hz with holes of 20–300 ms) windows of
  // degree 12–14 over 21–28 samples gave 29, 37 and 6,300 m/s next to holes, for a hand-held
  // camera under 1 m/s. So N ≤ (π/2)·length / (largest step) and, where an end step (which is
  // up to two steps at even spacing, the interval ending between samples) is more than
  // kEndHoleRatio mean steps, N²/m ≤ max_conditioning with m divided by that ratio. Even and
  // jittered sampling meet both.
  int TopDegree(const Span& span) const {
    double top = std::min<double>({static_cast<double>(options_.max_degree),
                                   std::floor(std::sqrt(options_.max_conditioning * span.count)),
                                   static_cast<double>(span.distinct - 1)});
    const double length = span.interval.b - span.interval.a;
    if (span.distinct >= 2 && length > 0.0 && span.largest_step > 0.0) {
      top = std::min(top, std::floor(0.5 * std::numbers::pi * length / span.largest_step));
      const double end_ratio = span.end_step * static_cast<double>(span.distinct - 1) / length;
      if (end_ratio > kEndHoleRatio) {
        top = std::min(top, std::floor(std::sqrt(options_.max_conditioning * span.count / end_ratio)));
      }
    }
    return std::max(1, static_cast<int>(top));
  }

  // The normal equations of each cross-validation fold (sample i in fold i mod kFolds) of the
  // samples centred on their mean, with Σz² per fold, and their sum. The folds keep their sums
  // only (NormalMoments), and a fold's matrix is built when it is held out: five matrices of
  // degree 400 held at once per thread were a fifth of a long recording's memory, each page of it
  // first touched at ~10 µs (docs/velocity.md, "Speed").
  static constexpr int kFolds = 5;
  struct Folds {
    std::vector<NormalMoments> parts;
    std::vector<Eigen::RowVectorXd> squares;
    NormalEquations total;
    Eigen::RowVectorXd mean;

    // The normal equations of the samples themselves: Σ T_k(x_i)(z_i - z̄) + z̄·Σ T_k(x_i), and
    // Σ T_k(x_i) = Σ T_k(x_i)T_0(x_i) is column 0 of the normal matrix.
    NormalEquations Uncentred() const {
      NormalEquations normal = total;
      normal.rhs += normal.gram.col(0) * mean;
      return normal;
    }
  };

  static Folds BuildFolds(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                          int top, const Interval& interval) {
    const Eigen::Index m = t.size(), d = z.cols();
    Folds folds;
    folds.mean = z.colwise().mean();
    for (int fold = 0; fold < kFolds; ++fold) {
      const Eigen::Index count = (m - fold + kFolds - 1) / kFolds;
      Eigen::VectorXd ft(count);
      Eigen::MatrixXd fz(count, d);
      for (Eigen::Index i = fold, k = 0; i < m; i += kFolds, ++k) {
        ft[k] = t[i];
        fz.row(k) = z.row(i) - folds.mean;
      }
      // A fold may have fewer samples than top + 1: its own system is then singular, which is fine
      // (only sums and products of it are used), so build it without the sample-count check.
      NormalMoments normal = BuildNormalMomentsUnchecked(ft, fz, top, interval);
      folds.squares.push_back(fz.colwise().squaredNorm());
      if (fold == 0) {
        folds.total = normal.Equations();
      } else {
        folds.total.gram += normal.Gram();
        folds.total.rhs += normal.rhs;
        folds.total.samples += normal.samples;
      }
      folds.parts.push_back(std::move(normal));
    }
    return folds;
  }

  // The highest degree the cross-validation of a window of top degree `top` tries, given the
  // degrees standardChop kept (`chopped`, the top where it found no plateau): twice the highest
  // plus 2. Above a plateau's start the coefficients are noise, which the held-out error of a
  // higher degree only matches by chance, and the folds' factorisations cost the cube of the
  // reach: the 37,500-sample windows of the 100k drone file (top 400, plateaus from 88 to 123,
  // cross-validated degrees 89 to 139) no longer factorise at 400 (docs/velocity.md, item 5 of
  // "Linear velocity").
  static int SearchReach(const std::vector<int>& chopped, int top) {
    return std::min(top, 2 * *std::max_element(chopped.begin(), chopped.end()) + 2);
  }

  // 5-fold cross-validation over a geometric grid of degrees up to `top`, per coordinate: the
  // degree of least held-out squared error. Nothing is evaluated point by point: with F_f the
  // normal equations (G_f, b_f) and Σz² of fold f, the training system of fold f is Σ F - F_f,
  // and the held-out error of coefficients c is Σz²_f - 2 cᵀb_f + cᵀG_f c. Each fold's training
  // system is factorised once; each candidate degree is then two triangular solves of a leading
  // block. The grid stops at `reach` (its first degree is always tried).
  static std::vector<int> CrossValidatedDegrees(const Folds& folds, int top, int reach, Eigen::VectorXd* best_error) {
    std::vector<int> grid = DegreeGrid(top);
    grid.erase(std::upper_bound(grid.begin() + 1, grid.end(), reach), grid.end());
    const Eigen::MatrixXd error = HeldOutErrors(folds, grid, grid.back());
    const Eigen::Index d = error.cols();
    std::vector<int> degrees(static_cast<size_t>(d));
    best_error->resize(d);
    for (Eigen::Index c = 0; c < d; ++c) {
      Eigen::Index best = 0;
      (*best_error)[c] = error.col(c).minCoeff(&best);
      degrees[static_cast<size_t>(c)] = grid[static_cast<size_t>(best)];
    }
    return degrees;
  }

  // The held-out squared error of each degree of `grid` (none above `top`, the folds' degree) and
  // coordinate: grid.size() x d.
  static Eigen::MatrixXd HeldOutErrors(const Folds& folds, const std::vector<int>& grid, int top) {
    const Eigen::Index d = folds.total.rhs.cols();
    Eigen::MatrixXd error = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(grid.size()), d);
    for (int fold = 0; fold < kFolds; ++fold) {
      const NormalEquations held_out = folds.parts[fold].Equations();
      NormalEquations train = folds.total;
      train.gram -= held_out.gram;
      train.rhs -= held_out.rhs;
      train.samples -= held_out.samples;
      // The training system may be singular above some degree: candidates above it score +inf.
      int solvable = top;
      std::optional<NestedCholesky> cholesky;
      while (!cholesky && solvable >= 0) {
        try {
          cholesky.emplace(train, solvable);
        } catch (const ComputeError&) {
          solvable = solvable > 8 ? static_cast<int>(0.8 * solvable) : solvable - 1;
        }
      }
      // The grid is ascending: the degrees a solvable training system can score come first.
      const auto solved = cholesky ? std::upper_bound(grid.begin(), grid.end(), solvable) - grid.begin() : 0;
      if (solved > 0) {
        error.topRows(solved) += cholesky->HeldOutErrors(train.rhs, held_out, folds.squares[fold],
                                                         std::vector<int>(grid.begin(), grid.begin() + solved));
      }
      error.bottomRows(static_cast<Eigen::Index>(grid.size()) - solved).setConstant(std::numeric_limits<double>::infinity());
    }
    return error;
  }

  const Eigen::VectorXd& t_;
  const Eigen::MatrixXd& z_;
  const internal::NoiseProfile& noise_;
  const CurveOptions& options_;
  const Eigen::VectorXd& rounding_;  // per coordinate, Curve's floor of σ (0: none)
  // The noise level's degrees of freedom where too few for kNoiseMargin to cover its scatter
  // (kMarginDof), else 0: the residual test's degree raise then allows for it.
  const double level_dof_;
};

int MaxDegree(const CurveWindow& window) { return *std::max_element(window.degrees.begin(), window.degrees.end()); }

// A window accepted while its residual is above the noise (lack-of-fit score above kSplitScore in
// some coordinate), or `undecided` (its coefficients could not show it resolved, WindowFitter::Fit),
// may still miss motion above its top degree that the residual test cannot prove at its length.
// Its two halves are fitted too, and it is split when they predict held-out samples better: their
// cross-validated squared error per sample, relative to the window's own and averaged over the
// coordinates, is below 1 (no σ is involved). Where only the coefficients spoke (undecided, the
// residual consistent with the noise) and its cross-validation had room (its degrees at most half
// its top, less one: SearchReach's rule) and wanted no more, the whole window is taken as right
// unless that ratio is below 1 by kSplitMargin of its scatter. (Near its top, a window may be too
// long for it, and any gain splits it.) With white noise of σ and models of p and p' parameters
// predicting the same m samples, the per-sample difference of their squared errors,
// (b − a)(2ε − a − b), has a variance of about 4σ⁴(p + p')/m, so the ratio has a standard deviation
// of 2·sqrt(p + p')/m per coordinate, p + p' the window's and both halves' parameters (measured
// over 60 clips of smooth motion, 0.5 s at 100 Hz under 2 mm: 0.079 for the mean over three
// coordinates, against 0.072 from the formula).
// A window fitted without splitting, its held-out errors, and whether FitCore may take it as
// the fit of its core (WindowFitter::Fit's `reusable`).
struct HalfFit {
  CurveWindow window;
  Eigen::VectorXd held_out;
  bool reusable = false;
};

bool SplitPredictsBetter(const WindowFitter& fitter, const CurveWindow& window, const Eigen::VectorXd& held_out,
                         const CurveSegment& segment, const CurveOptions& options, bool undecided,
                         std::array<std::optional<HalfFit>, 2>* halves) {
  if (options.degree_method != DegreeMethod::kCrossValidation || !options.lack_of_fit || held_out.size() == 0) {
    return false;
  }
  if (!(undecided || window.lack_of_fit.maxCoeff() > kSplitScore) || !(held_out.minCoeff() > 0.0)) return false;
  const double middle = 0.5 * (window.core_begin + window.core_end);
  for (int k = 0; k < 2; ++k) {
    HalfFit half;
    half.window = *fitter.Fit(k == 0 ? window.core_begin : middle, k == 0 ? middle : window.core_end, segment.begin,
                              segment.end, false, &half.held_out, nullptr, nullptr, &half.reusable);
    (*halves)[static_cast<size_t>(k)] = std::move(half);
  }
  const HalfFit &left = *(*halves)[0], &right = *(*halves)[1];
  const double m_left = static_cast<double>(left.window.samples), m_right = static_cast<double>(right.window.samples);
  const Eigen::VectorXd error = (m_left * left.held_out + m_right * right.held_out) / (m_left + m_right);
  const Eigen::Index d = held_out.size();
  const int top = static_cast<int>(window.coefficient_magnitudes.rows()) - 1;  // the probe's degree
  double margin = 0.0;
  if (undecided && 2 * MaxDegree(window) + 2 <= top) {
    double variance = 0.0;  // of the mean ratio over the coordinates
    const double m = static_cast<double>(window.samples);
    for (Eigen::Index c = 0; c < d; ++c) {
      const auto k = static_cast<size_t>(c);
      const double parameters = window.degrees[k] + left.window.degrees[k] + right.window.degrees[k] + 3.0;
      variance += 4.0 * parameters / (m * m);
    }
    margin = kSplitMargin * std::sqrt(variance) / static_cast<double>(d);
  }
  return error.cwiseQuotient(held_out).mean() < 1.0 - margin;
}

// Whether the local regression may gain in some window of the segments (not a segment's first
// or last window: their rate is the end caps').
bool RegressionMayGainSomewhere(const std::vector<CurveSegment>& segments) {
  for (const CurveSegment& segment : segments) {
    for (size_t k = 1; k + 1 < segment.windows.size(); ++k) {
      if (internal::RegressionMayGain(segment.windows[k])) return true;
    }
  }
  return false;
}

// The samples of sorted times t in [a, b].
Eigen::Index SamplesIn(const Eigen::VectorXd& t, double a, double b) {
  return std::upper_bound(t.data(), t.data() + t.size(), b) - std::lower_bound(t.data(), t.data() + t.size(), a);
}

// The fewest samples an end window's core needs to be halved further (RefineEnds).
Eigen::Index EndWindowMinimum(const CurveOptions& options) {
  return 2 * std::max<Eigen::Index>(options.min_window_samples, kMinEndWindowSamples);
}

// A core [a, b] of segment `segment` to fit adaptively (FitCore): whether it is a piece of a
// window split for missed motion, whether it is the end window RefineEnds would cut (below) and,
// when SplitPredictsBetter fitted it already, that fit.
struct Core {
  size_t segment = 0;
  double a = 0, b = 0;
  bool piece = false, end_piece = false;
  std::optional<HalfFit> fitted = std::nullopt;
};

// The order in which one thread fits cores (from a stack, left halves first): by segment, then
// start, then the longer first (a core before its halves).
std::tuple<size_t, double, double> CoreOrder(const Core& core) { return {core.segment, core.a, -core.b}; }

// Fits a core of `segment` adaptively: returns its window when it is accepted, else pushes the two
// halves it is cut into (the right one first, so that the left is taken first from a stack). A
// core is halved until its series resolves or it gets too small to split; each core depends on
// nothing but its own fields, so cores may be fitted in any order.
template <typename Push>
std::optional<CurveWindow> FitCore(const WindowFitter& fitter, const Eigen::VectorXd& t, const CurveSegment& segment,
                                   const CurveOptions& options, Core core, Push&& push) {
  const double a = core.a, b = core.b;
  const bool end_piece = core.end_piece;
  std::optional<HalfFit>& fitted = core.fitted;
  auto cut = [&](bool left_end, bool right_end, bool pieces, std::array<std::optional<HalfFit>, 2> halves) {
    const double middle = 0.5 * (a + b);
    push(Core{core.segment, middle, b, pieces, right_end, std::move(halves[1])});
    push(Core{core.segment, a, middle, pieces, left_end, std::move(halves[0])});
  };
  const Eigen::Index inside = SamplesIn(t, a, b);
  // Halves of a core across a hole can be nearly empty (a lone sample joined to a segment across
  // a gap): each must keep half the smallest window's samples.
  const Eigen::Index smaller_half = std::min(SamplesIn(t, a, 0.5 * (a + b)), SamplesIn(t, 0.5 * (a + b), b));
  const bool halves_hold = 2 * smaller_half >= options.min_window_samples;
  const bool may_split = inside >= 2 * options.min_window_samples && halves_hold;
  // A window at an end of its segment whose degree exceeds end_degree is cut by RefineEnds when
  // it is accepted and split when it is not. When that degree is certain, it is cut here unfitted,
  // as RefineEnds would: the outer half is the end window to refine further (fitted without
  // splitting, halved again while its degree exceeds end_degree), the inner half an ordinary core.
  // A whole segment is cut at its front first, like RefineEnds does.
  const bool front = a == segment.begin, back = b == segment.end;
  const bool refine_ends = options.end_degree > 0 && options.degree_method == DegreeMethod::kCrossValidation;
  const bool refinable = refine_ends && (front || back) && inside >= EndWindowMinimum(options) && halves_hold;
  if (refinable && !fitted && fitter.DegreeCertainlyAbove(a, b, segment.begin, segment.end, options.end_degree)) {
    bool subsample_unresolved = false;
    if (end_piece || fitter.ResolvedAtTop(a, b, segment.begin, segment.end, &subsample_unresolved)) {
      cut(front, back && !front, false, {});
      return std::nullopt;
    }
    // What Fit would do after the same subsample probe: on a long recording, that probe of the
    // whole segment and of its halves was taken twice.
    if (subsample_unresolved && may_split) {
      cut(false, false, core.piece, {});
      return std::nullopt;
    }
  }
  Eigen::VectorXd held_out;
  bool undecided = false, missed = false;
  std::optional<CurveWindow> window;
  if (end_piece) {
    window = fitter.Fit(a, b, segment.begin, segment.end, false);
    if (refinable && MaxDegree(*window) > options.end_degree) {
      cut(front, !front, false, {});
      return std::nullopt;
    }
  } else if (fitted && (!may_split || fitted->reusable)) {
    // The fit SplitPredictsBetter made without splitting is this one when splitting is not
    // allowed here either, or when it says the same call with splitting would return it.
    window = std::move(fitted->window);
    held_out = std::move(fitted->held_out);
  } else {
    window = fitter.Fit(a, b, segment.begin, segment.end, may_split, &held_out, &undecided, &missed);
  }
  std::array<std::optional<HalfFit>, 2> halves;
  if (window && may_split && !end_piece &&
      SplitPredictsBetter(fitter, *window, held_out, segment, options, undecided, &halves)) {
    // Missed motion when its residual said so; a window split because its coefficients could
    // not show it resolved (undecided) is only too long for its top degree.
    missed = window->lack_of_fit.maxCoeff() > kSplitScore;
    window.reset();
  }
  if (!window) {
    cut(false, false, core.piece || missed, std::move(halves));
    return std::nullopt;
  }
  window->missed_motion = core.piece;
  return window;
}

// Fits cores [a0, b0] of a segment adaptively (FitCore), on the caller's thread. Windows come out
// in time order.
std::vector<CurveWindow> FitAdaptive(const WindowFitter& fitter, const Eigen::VectorXd& t, const CurveSegment& segment,
                                     double a0, double b0, const CurveOptions& options) {
  std::vector<CurveWindow> windows;
  internal::DrainWork(
      std::vector<Core>{Core{0, a0, b0}}, 1,
      [&](Core core, auto&& push) {
        if (std::optional<CurveWindow> window = FitCore(fitter, t, segment, options, std::move(core), push)) {
          windows.push_back(std::move(*window));
        }
      },
      CoreOrder);
  return windows;
}

// The windows that replace a segment's end window `end` (its first with `front`, else its last):
// it is halved while its degree exceeds options.end_degree and it keeps enough samples to be
// split; the inner half is refitted adaptively (it may need splitting itself).
std::vector<CurveWindow> RefineEnd(const WindowFitter& fitter, const Eigen::VectorXd& t, const CurveSegment& segment,
                                   CurveWindow end_window, bool front, const CurveOptions& options) {
  const Eigen::Index minimum = EndWindowMinimum(options);
  std::vector<CurveWindow> windows{std::move(end_window)};
  while (true) {
    const CurveWindow& end = front ? windows.front() : windows.back();
    if (MaxDegree(end) <= options.end_degree || SamplesIn(t, end.core_begin, end.core_end) < minimum) break;
    // Halving one step at a time fits every outer half on the way and drops all but the last.
    // A resolved motion needs a degree about proportional to the window's length, so the cuts
    // the halvings are expected to make are taken at once (each halved piece holding enough
    // samples), and the end piece is checked from there back outwards: while the next larger
    // piece would already have stopped the halving (degree at most end_degree), it is the end
    // piece. The windows are those the one-by-one halving leaves (its degrees fall as its length
    // does), for two fits of the end piece instead of one per halving. Cross-validated degrees
    // follow the length; standardChop's jump to the noise plateau and do not, so with it the
    // end window is halved one step at a time.
    const double a = end.core_begin, b = end.core_end;
    const bool predict = options.degree_method == DegreeMethod::kCrossValidation;
    std::vector<double> cuts{front ? b : a};  // from the inside out
    for (double degree = MaxDegree(end); degree > options.end_degree && (predict || cuts.size() < 2); degree *= 0.5) {
      if (cuts.size() > 1 && (front ? SamplesIn(t, a, cuts.back()) : SamplesIn(t, cuts.back(), b)) < minimum) break;
      cuts.push_back(front ? 0.5 * (a + cuts.back()) : 0.5 * (cuts.back() + b));
    }
    auto fit_end = [&](double cut) {
      return front ? *fitter.Fit(a, cut, segment.begin, segment.end, false)
                   : *fitter.Fit(cut, b, segment.begin, segment.end, false);
    };
    CurveWindow outer = fit_end(cuts.back());
    while (cuts.size() > 2 && MaxDegree(outer) <= options.end_degree) {
      CurveWindow larger = fit_end(cuts[cuts.size() - 2]);
      if (MaxDegree(larger) > options.end_degree) break;
      cuts.pop_back();
      outer = std::move(larger);
    }
    std::vector<CurveWindow> refined;
    auto append = [&refined](std::vector<CurveWindow> more) {
      refined.insert(refined.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
    };
    if (front) {
      refined.push_back(std::move(outer));
      for (size_t k = cuts.size() - 1; k >= 1; --k) append(FitAdaptive(fitter, t, segment, cuts[k], cuts[k - 1], options));
      windows.erase(windows.begin());
      windows.insert(windows.begin(), std::make_move_iterator(refined.begin()), std::make_move_iterator(refined.end()));
    } else {
      for (size_t k = 1; k < cuts.size(); ++k) append(FitAdaptive(fitter, t, segment, cuts[k - 1], cuts[k], options));
      refined.push_back(std::move(outer));
      windows.pop_back();
      windows.insert(windows.end(), std::make_move_iterator(refined.begin()), std::make_move_iterator(refined.end()));
    }
  }
  return windows;
}

// Refines the first and the last window of a segment (RefineEnd), the front first. With two
// windows or more the two ends do not touch and are refined on up to `threads` threads.
void RefineEnds(const WindowFitter& fitter, const Eigen::VectorXd& t, CurveSegment& segment,
                const CurveOptions& options, int threads) {
  if (options.end_degree <= 0) return;
  std::vector<CurveWindow>& windows = segment.windows;
  if (windows.size() == 1) {
    windows = RefineEnd(fitter, t, segment, std::move(windows.front()), true, options);
    std::vector<CurveWindow> back = RefineEnd(fitter, t, segment, std::move(windows.back()), false, options);
    windows.pop_back();
    windows.insert(windows.end(), std::make_move_iterator(back.begin()), std::make_move_iterator(back.end()));
    return;
  }
  std::array<std::vector<CurveWindow>, 2> ends;
  internal::ParallelFor(2, threads, [&](int side) {
    const bool front = side == 0;
    ends[static_cast<size_t>(side)] = RefineEnd(fitter, t, segment, front ? windows.front() : windows.back(), front, options);
  });
  std::vector<CurveWindow> refined = std::move(ends[0]);
  refined.insert(refined.end(), std::make_move_iterator(windows.begin() + 1), std::make_move_iterator(windows.end() - 1));
  refined.insert(refined.end(), std::make_move_iterator(ends[1].begin()), std::make_move_iterator(ends[1].end()));
  windows = std::move(refined);
}

// Up to 4 coordinates, on the stack: evaluation allocates nothing.
using Point = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;

// Σ_k c_k T_k(x) for each column of `coefficients`, times `scale`, into `out`.
void ClenshawInto(const Eigen::MatrixXd& coefficients, double x, double scale, Point* out) {
  const Eigen::Index n = coefficients.rows() - 1, d = coefficients.cols();
  out->resize(d);
  const double two_x = 2.0 * x;
  for (Eigen::Index c = 0; c < d; ++c) {
    const double* a = coefficients.col(c).data();
    double b1 = 0.0, b2 = 0.0;
    for (Eigen::Index k = n; k >= 1; --k) {
      const double b0 = two_x * b1 - b2 + a[k];
      b2 = b1;
      b1 = b0;
    }
    (*out)[c] = (x * b1 - b2 + a[0]) * scale;
  }
}

// Value, and the derivatives up to `order` (0, 1 or 2), of a window at time t.
void EvaluateWindow(const CurveWindow& w, double t, int order, Point* p, Point* v, Point* a) {
  const double x = w.series.interval.ToUnit(t);
  const double scale = w.series.interval.DerivativeScale();
  ClenshawInto(w.series.coefficients, x, 1.0, p);
  if (order >= 1) ClenshawInto(w.first_derivative, x, scale, v);
  if (order >= 2) ClenshawInto(w.second_derivative, x, scale * scale, a);
}

}  // namespace

void Smoothstep(double u, double* s, double* ds, double* dds) {
  u = std::clamp(u, 0.0, 1.0);
  *s = u * u * u * (u * (6.0 * u - 15.0) + 10.0);
  *ds = 30.0 * u * u * (1.0 - u) * (1.0 - u);
  *dds = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u);
}

void CurveOptions::Validate() const {
  const OptionCheck check("CurveOptions");
  check(degree_method != DegreeMethod::kFixed || fixed_degree >= 0, "fixed_degree",
        "must be a non-negative integer, got {}", fixed_degree);
  check(!window_s || (*window_s > 0.0 && std::isfinite(*window_s)), "window_s",
        "must be a positive number of seconds, got {}", window_s.value_or(0.0));
  check(max_conditioning > 0.0, "max_conditioning", "must be positive, got {}", max_conditioning);
  check(max_degree >= 1, "max_degree", "must be at least 1, got {}", max_degree);
  check(min_window_samples >= 2, "min_window_samples", "must be at least 2, got {}", min_window_samples);
  check(overlap >= 0.0 && overlap <= 1.0, "overlap", "must be in [0, 1], got {}", overlap);
  check(gap_factor > 1.0, "gap_factor", "must be greater than 1, got {}", gap_factor);
  check(min_gap_s >= 0.0, "min_gap_s", "must be non-negative, got {}", min_gap_s);
  check(!noise_sigma || (*noise_sigma >= 0.0 && std::isfinite(*noise_sigma)), "noise_sigma",
        "must be a non-negative number, got {}", noise_sigma.value_or(0.0));
  check(resolution >= 0.0 && std::isfinite(resolution), "resolution", "must be a non-negative number, got {}",
        resolution);
  check(end_degree >= 0, "end_degree", "must be non-negative (0: no end refinement), got {}", end_degree);
  check(threads >= 0 && threads <= internal::kMaxThreads, "threads", "must be in 0..{} (0: every core), got {}",
        internal::kMaxThreads, threads);
}

Curve FitCurve(std::span<const int64_t> stamps_ns, const Eigen::Ref<const Eigen::MatrixXd>& values,
               const CurveOptions& options) {
  options.Validate();
  const auto m = static_cast<Eigen::Index>(stamps_ns.size());
  if (values.rows() != m) throw std::invalid_argument("FitCurve: stamps and values differ in length");
  if (values.cols() < 1 || values.cols() > 4) throw std::invalid_argument("FitCurve: 1..4 coordinates");
  if (m < 2) throw ComputeError(fmt::format("a fit needs at least 2 samples, got {}", m));
  const int threads = m >= kParallelSamples ? internal::ThreadCount(options.threads) : 1;

  std::vector<Eigen::Index> order(m);
  std::iota(order.begin(), order.end(), 0);
  if (!std::is_sorted(stamps_ns.begin(), stamps_ns.end())) {
    std::stable_sort(order.begin(), order.end(), [&](Eigen::Index i, Eigen::Index j) { return stamps_ns[i] < stamps_ns[j]; });
  }
  Curve curve;
  curve.origin_ns_ = stamps_ns[order.front()];
  curve.threads_ = options.threads;
  curve.dimension_ = static_cast<int>(values.cols());
  Eigen::VectorXd t(m);
  Eigen::MatrixXd z(m, values.cols());
  for (Eigen::Index i = 0; i < m; ++i) {
    t[i] = static_cast<double>(stamps_ns[order[i]] - curve.origin_ns_) * 1e-9;
    z.row(i) = values.row(order[i]);
  }
  if (t[m - 1] == 0.0) throw ComputeError(fmt::format("all {} stamps are equal: there is no time to fit over", m));

  std::vector<double> dts;
  dts.reserve(static_cast<size_t>(m - 1));
  for (Eigen::Index i = 1; i < m; ++i) {
    if (t[i] > t[i - 1]) dts.push_back(t[i] - t[i - 1]);
  }
  const double gap = std::max(options.gap_factor * internal::SelectNonNegative(&dts, dts.size() / 2), options.min_gap_s);
  // Boundaries b (between sorted samples b and b + 1) where the data are split.
  std::vector<Eigen::Index> gaps;
  for (Eigen::Index i = 1; i < m; ++i) {
    if (t[i] - t[i - 1] > gap) gaps.push_back(i - 1);
  }

  // Values rounded to a lattice carry its noise, q/sqrt(12), also where the differences see less
  // (a staircase: motion slower than a step a sample), and more with noise added before the
  // rounding, which the median of whole-step differences reads coarsely (RoundingLevel); an
  // estimate is floored where they were rounded, not where exact motion lies on a lattice by
  // itself (IsRounded). A clean staircase is placed between its steps instead (PlaceBetweenSteps),
  // and its floor is how well its crossings predict each other. Its errors are no longer the
  // rounding's, so the rounding's two-sided degree test is not made on it (curve.rounding_ is 0
  // there); the local regression leaves it alone all the same (curve.staircase_). A step given by
  // the caller is not one the values need lie on, and they are left as they are.
  curve.resolution_ = Eigen::VectorXd::Zero(z.cols());
  curve.rounding_ = Eigen::VectorXd::Zero(z.cols());
  curve.staircase_.assign(static_cast<size_t>(z.cols()), false);
  Eigen::VectorXd sigma_floor = Eigen::VectorXd::Zero(z.cols());
  for (Eigen::Index c = 0; c < z.cols(); ++c) {
    const double q = options.resolution > 0.0 ? options.resolution : FindResolution(z.col(c));
    curve.resolution_[c] = q;
    if (options.resolution > 0.0) {
      curve.rounding_[c] = q / std::sqrt(12.0);
      sigma_floor[c] = curve.rounding_[c];
      continue;
    }
    if (!(q > 0.0) || z.rows() < 5) continue;
    const Eigen::VectorXd steps = internal::WholeSteps(z.col(c), q);
    if (!internal::IsRoundedSteps(steps)) continue;
    curve.rounding_[c] = internal::RoundingLevel(steps, q, gaps);
    sigma_floor[c] = curve.rounding_[c];
    if (const std::optional<double> placed = internal::PlaceBetweenSteps(t, z.col(c), steps, q, gaps)) {
      sigma_floor[c] = *placed;
      curve.rounding_[c] = 0.0;
      curve.staircase_[static_cast<size_t>(c)] = true;
    }
  }
  auto floored = [&](Eigen::VectorXd sigma) { return sigma.cwiseMax(sigma_floor).eval(); };
  // The step of each coordinate whose values were rounded to it and stay so (0: none), for the
  // noise profile: where the rounding dominates their errors, these change with the speed.
  Eigen::VectorXd rounded = Eigen::VectorXd::Zero(z.cols());
  for (Eigen::Index c = 0; c < z.cols(); ++c) rounded[c] = curve.rounding_[c] > 0.0 ? curve.resolution_[c] : 0.0;

  // Jumps and glitches (CurveOptions::robust): outliers leave the fit, jumps split it.
  internal::Jumps jumps;
  Eigen::VectorXd noise;  // of the samples split at the gaps
  // The noise profile before the search (its jumps and glitches read as noise there too) floors
  // the search's scale where the samples are noisier: against the recording's σ a burst's slopes
  // were taken for jumps. Where the search finds nothing, it is the fit's profile as well.
  std::optional<internal::NoiseProfile> before;
  if (options.robust) {
    // The differences go before the search, which needs only the profile: they take 96 bytes a
    // sample, and a page first touched costs ~10 µs (docs/velocity.md, "Speed").
    std::optional<internal::DifferenceMagnitudes> magnitudes;
    if (!options.noise_sigma) magnitudes.emplace(t, z, gaps, threads);
    noise = options.noise_sigma ? Eigen::VectorXd::Constant(values.cols(), *options.noise_sigma)
                                : floored(magnitudes->Sigma(0, m));
    if (magnitudes) before.emplace(noise, *magnitudes, m, rounded);
    magnitudes.reset();
    jumps = internal::FindJumps(t, z, gaps, noise, before ? &*before : nullptr, threads);
  }
  std::vector<char> kept(static_cast<size_t>(m), 1);
  for (const Eigen::Index i : jumps.outliers) {
    kept[static_cast<size_t>(i)] = 0;
    curve.outlier_times_.push_back(t[i]);
  }
  for (const Eigen::Index b : jumps.breaks) curve.jump_times_.push_back(0.5 * (t[b] + t[b + 1]));
  // Steps leave the samples after them (sorted numbering, before outliers go) and return in the values.
  curve.step_offsets_.resize(static_cast<Eigen::Index>(jumps.steps.size()), z.cols());
  {
    Eigen::RowVectorXd offset = Eigen::RowVectorXd::Zero(z.cols());
    size_t next = 0;
    for (Eigen::Index i = 0; i < m; ++i) {
      if (next < jumps.steps.size() && jumps.steps[next].first == i - 1) {
        offset += jumps.steps[next].second.transpose();
        curve.step_times_.push_back(0.5 * (t[i - 1] + t[i]));
        curve.step_offsets_.row(static_cast<Eigen::Index>(next)) = offset;
        ++next;
      }
      z.row(i) -= offset;
    }
  }
  // The samples fitted, and the boundaries in their numbering (a boundary after sample b becomes
  // one after the last kept sample up to b).
  std::vector<Eigen::Index> fitted_index(static_cast<size_t>(m));
  Eigen::Index fitted_count = 0;
  for (Eigen::Index i = 0; i < m; ++i) {
    fitted_index[static_cast<size_t>(i)] = fitted_count;
    fitted_count += kept[static_cast<size_t>(i)];
  }
  if (fitted_count < m) {
    Eigen::VectorXd ft(fitted_count);
    Eigen::MatrixXd fz(fitted_count, z.cols());
    for (Eigen::Index i = 0, k = 0; i < m; ++i) {
      if (!kept[static_cast<size_t>(i)]) continue;
      ft[k] = t[i];
      fz.row(k++) = z.row(i);
    }
    t = std::move(ft);
    z = std::move(fz);
  }
  // (boundary, is a jump) in the fitted numbering, ascending.
  std::vector<std::pair<Eigen::Index, bool>> boundaries;
  auto add_boundary = [&](Eigen::Index b, bool jump) {
    Eigen::Index last_kept = fitted_index[static_cast<size_t>(b)] + kept[static_cast<size_t>(b)] - 1;
    // Samples at one stamp stay in one segment (segments must not share a time): a jump found
    // between two of them moves past the last.
    while (last_kept >= 0 && last_kept + 1 < fitted_count && t[last_kept + 1] == t[last_kept]) ++last_kept;
    if (last_kept >= 0 && last_kept + 1 < fitted_count) boundaries.emplace_back(last_kept, jump);
  };
  for (const Eigen::Index b : gaps) add_boundary(b, false);
  for (const Eigen::Index b : jumps.breaks) add_boundary(b, true);
  std::sort(boundaries.begin(), boundaries.end());
  boundaries.erase(std::unique(boundaries.begin(), boundaries.end(),
                               [](const auto& x, const auto& y) { return x.first == y.first; }),
                   boundaries.end());
  std::vector<Eigen::Index> cuts;
  for (const auto& [b, jump] : boundaries) cuts.push_back(b);

  // Taken again where the search found something (fewer samples, steps out, more cuts).
  const bool found = !jumps.outliers.empty() || !jumps.steps.empty() || !jumps.breaks.empty();
  std::optional<internal::DifferenceMagnitudes> magnitudes;  // of the samples fitted, for their noise profile
  if (!options.noise_sigma && (found || !before)) magnitudes.emplace(t, z, cuts, threads);
  curve.noise_sigma_ = options.noise_sigma ? Eigen::VectorXd::Constant(values.cols(), *options.noise_sigma)
                       : noise.size() > 0 && !found ? noise
                                                    : floored(magnitudes->Sigma(0, fitted_count));
  // A noise σ given is taken everywhere; an estimated one is raised over stretches that are clearly
  // noisier than the data as a whole.
  const internal::NoiseProfile profile =
      before && !found ? std::move(*before)
      : magnitudes     ? internal::NoiseProfile(curve.noise_sigma_, *magnitudes, fitted_count, rounded)
                       : internal::NoiseProfile(curve.noise_sigma_);
  before.reset();
  magnitudes.reset();
  curve.noisier_samples_ = profile.raised_samples();
  if (profile.varies()) curve.noise_sigma_max_ = profile.maximum();
  if (profile.stamp_noise()) curve.stamp_noise_s_ = std::sqrt(profile.stamp_noise()->variance);
  // An estimated level's own scatter, where kNoiseMargin does not cover it (a short recording).
  // Under kWinsorizedBelow samples the winsorized scale's, also where a coordinate kept the median
  // for its heavy tails (with the median's for every short recording the clips' errors were the
  // same; docs/velocity.md, "Short recordings").
  const double samples_per_dof = fitted_count < internal::DifferenceMagnitudes::kWinsorizedBelow
                                     ? kSamplesPerWinsorizedDof
                                     : kSamplesPerNoiseDof;
  const double level_dof = options.noise_sigma ? 0.0 : static_cast<double>(fitted_count) / samples_per_dof;
  const double uncertain_level_dof = level_dof < kMarginDof ? level_dof : 0.0;
  const WindowFitter fitter(t, z, profile, options, curve.rounding_, uncertain_level_dof);

  // Segment boundaries [starts[k], starts[k+1]), with whether each segment ends at a jump; a
  // segment with one distinct stamp joins the neighbour across the shorter gap.
  std::vector<Eigen::Index> starts{0};
  std::vector<char> at_jump;
  for (const auto& [b, jump] : boundaries) {
    starts.push_back(b + 1);
    at_jump.push_back(jump ? 1 : 0);
  }
  starts.push_back(fitted_count);
  at_jump.push_back(0);
  for (size_t k = 0; k + 1 < starts.size() && starts.size() > 2;) {
    if (t[starts[k + 1] - 1] != t[starts[k]]) {
      ++k;
      continue;
    }
    const double left_gap = k > 0 ? t[starts[k]] - t[starts[k] - 1] : std::numeric_limits<double>::infinity();
    const double right_gap = k + 2 < starts.size() ? t[starts[k + 1]] - t[starts[k + 1] - 1]
                                                   : std::numeric_limits<double>::infinity();
    const size_t removed = left_gap <= right_gap ? k : k + 1;
    // The boundary before starts[removed] goes: the joined segment ends where the later one did.
    at_jump.erase(at_jump.begin() + static_cast<std::ptrdiff_t>(removed - 1));
    starts.erase(starts.begin() + static_cast<std::ptrdiff_t>(removed));
    if (k > 0) --k;
  }

  ReportProgress(options.progress, "fitting windows", 0, fitted_count);
  const bool fixed_windows = options.single_window || options.window_s.has_value();  // else adaptive
  for (size_t k = 0; k + 1 < starts.size(); ++k) {
    CurveSegment& segment = curve.segments_.emplace_back();
    segment.begin = t[starts[k]];
    segment.end = t[starts[k + 1] - 1];
    segment.continues = at_jump[k] != 0;
    if (!fixed_windows) continue;
    const int cores = options.single_window
                          ? 1
                          : std::max(1, static_cast<int>(std::lround((segment.end - segment.begin) / *options.window_s)));
    for (int c = 0; c < cores; ++c) {
      const double a = segment.begin + (segment.end - segment.begin) * c / cores;
      const double b = c + 1 == cores ? segment.end : segment.begin + (segment.end - segment.begin) * (c + 1) / cores;
      segment.windows.push_back(*fitter.Fit(a, b, segment.begin, segment.end, false));
    }
  }
  if (!fixed_windows) {
    // The cores of all segments are fitted on the threads; each thread's windows wait under the
    // lock in their segment and are put in time order once all are fitted.
    std::vector<Core> roots;
    for (size_t k = curve.segments_.size(); k-- > 0;) {  // the first segment on top of the stack
      roots.push_back(Core{k, curve.segments_[k].begin, curve.segments_[k].end});
    }
    std::vector<std::vector<CurveWindow>> windows(curve.segments_.size());
    std::mutex windows_mutex;
    Eigen::Index done = 0;
    internal::DrainWork(
        std::move(roots), threads,
        [&](Core core, auto&& push) {
          const size_t k = core.segment;
          const CurveSegment& segment = curve.segments_[k];
          // The samples of [a, b), and the segment's last with its last core: the cores tile them.
          const double *begin = t.data(), *end = t.data() + t.size();
          const Eigen::Index inside =
              (core.b == segment.end ? std::upper_bound(begin, end, core.b) : std::lower_bound(begin, end, core.b)) -
              std::lower_bound(begin, end, core.a);
          std::optional<CurveWindow> window = FitCore(fitter, t, segment, options, std::move(core), push);
          if (!window) return;
          const std::lock_guard<std::mutex> lock(windows_mutex);
          windows[k].push_back(std::move(*window));
          done += inside;
          ReportProgress(options.progress, "fitting windows", done, fitted_count);
        },
        CoreOrder);
    for (size_t k = 0; k < windows.size(); ++k) {
      CurveSegment& segment = curve.segments_[k];
      segment.windows = std::move(windows[k]);
      std::sort(segment.windows.begin(), segment.windows.end(), [](const CurveWindow& x, const CurveWindow& y) {
        return std::tie(x.core_begin, x.core_end) < std::tie(y.core_begin, y.core_end);
      });
      RefineEnds(fitter, t, segment, options, threads);
    }
  }

  const bool adaptive = !fixed_windows && options.degree_method != DegreeMethod::kFixed;
  std::vector<int64_t> sorted;  // the fitted samples' stamps
  sorted.reserve(static_cast<size_t>(fitted_count));
  for (Eigen::Index i = 0; i < m; ++i) {
    if (kept[static_cast<size_t>(i)]) sorted.push_back(stamps_ns[order[i]]);
  }
  if (options.end_caps && adaptive) {
    // A segment's caps are chosen before they are inserted, and evaluating one segment's samples
    // uses only its own windows.
    const internal::VelocityAt velocity = [&](Eigen::Index first, Eigen::Index count) {
      Eigen::MatrixXd ignored, derivative;
      curve.EvaluateMany(std::span<const int64_t>(sorted).subspan(static_cast<size_t>(first), static_cast<size_t>(count)),
                         1, &ignored, &derivative);
      return derivative;
    };
    for (size_t k = 0; k + 1 < starts.size(); ++k) {
      const bool front_at_jump = k > 0 && curve.segments_[k - 1].continues;
      internal::AddEndCaps(t, z, velocity, starts[k], starts[k + 1], front_at_jump, options.short_segment_caps,
                           &curve.segments_[k], threads);
    }
    // Then fits across the gaps take over the segments' ends where they are the better estimate.
    internal::BridgeGaps(t, z, starts, profile, sigma_floor, &curve.segments_, threads);
  }

  // Where windows clearly missed motion, the samples' own local interpolant (docs/velocity.md).
  std::vector<internal::LocalRates> local_rates;  // per segment
  bool any_under_resolved = false;
  if (options.lack_of_fit && adaptive) {
    for (size_t k = 0; k + 1 < starts.size(); ++k) {
      local_rates.push_back(
          internal::UnderResolvedRates(t, z, starts[k], starts[k + 1], curve.segments_[k], profile));
      any_under_resolved = any_under_resolved || local_rates.back().under_resolved.any();
    }
  }
  // The windows' fit at the samples (without the steps, as z), and per segment the local samples.
  Eigen::MatrixXd window_values, window_rates;
  std::vector<internal::LocalSamples> local_samples;
  if (options.lack_of_fit && adaptive && (curve.unresolved_windows() > 0 || any_under_resolved)) {
    curve.EvaluateMany(sorted, 1, &window_values, &window_rates);
    for (Eigen::Index i = 0; i < fitted_count; ++i) {
      if (const Eigen::Index k = curve.StepsBefore(t[i]); k > 0) window_values.row(i) -= curve.step_offsets_.row(k - 1);
    }
    for (size_t k = 0; k + 1 < starts.size(); ++k) {
      local_samples.push_back(internal::ChooseLocalSamples(t, starts[k], starts[k + 1], curve.segments_[k],
                                                           local_rates[k], window_rates, profile, kLackOfFitLimit));
      std::vector<LocalRun> runs = internal::BuildLocalRuns(t, z, starts[k], starts[k + 1], local_samples.back(),
                                                            window_values, window_rates, profile);
      std::move(runs.begin(), runs.end(), std::back_inserter(curve.local_runs_));
    }
  }
  // Where windows were split for missed motion, a local polynomial regression where it predicts
  // the rate better than the windows or the local interpolant (docs/velocity.md, "Local
  // regression"); the local interpolant's samples inside its runs are given over to it.
  if (options.lack_of_fit && options.local_regression && adaptive && RegressionMayGainSomewhere(curve.segments_)) {
    Eigen::MatrixXd fit_values, fit_rates;
    curve.EvaluateMany(sorted, 1, &fit_values, &fit_rates);
    for (Eigen::Index i = 0; i < fitted_count; ++i) {  // the fitted values without the steps, as z
      if (const Eigen::Index k = curve.StepsBefore(t[i]); k > 0) fit_values.row(i) -= curve.step_offsets_.row(k - 1);
    }
    const bool local = !local_samples.empty();
    // The segments are independent: each on whichever thread takes it, the runs in segment order.
    const auto segment_count = static_cast<int>(starts.size()) - 1;
    std::vector<std::vector<LocalRun>> segment_runs(static_cast<size_t>(segment_count));
    internal::ParallelFor(segment_count, threads, [&](int k) {
      segment_runs[static_cast<size_t>(k)] = internal::LocalRegressionRuns(
          t, z, starts[k], starts[k + 1], curve.segments_[k], local ? window_values : fit_values,
          local ? window_rates : fit_rates, fit_values, fit_rates, local ? &local_samples[k] : nullptr, profile,
          curve.rounding_, curve.staircase_);
    });
    std::vector<LocalRun> regression;
    for (size_t k = 0; k + 1 < starts.size(); ++k) {
      std::vector<LocalRun>& runs = segment_runs[k];
      if (local) {
        const Eigen::Index n = starts[k + 1] - starts[k];
        for (const LocalRun& run : runs) {
          const auto [from, to] = internal::SamplesOf(t, starts[k], n, run);
          if (to <= from) continue;
          local_samples[k].local.middleRows(from, to - from).setConstant(false);
          local_samples[k].modelled.middleRows(from, to - from).setConstant(false);
        }
      }
      std::move(runs.begin(), runs.end(), std::back_inserter(regression));
    }
    if (!regression.empty()) {
      std::vector<LocalRun> all = std::move(regression);
      for (size_t k = 0; local && k + 1 < starts.size(); ++k) {
        std::vector<LocalRun> built = internal::BuildLocalRuns(t, z, starts[k], starts[k + 1], local_samples[k],
                                                               window_values, window_rates, profile);
        std::move(built.begin(), built.end(), std::back_inserter(all));
      }
      std::sort(all.begin(), all.end(), [](const LocalRun& x, const LocalRun& y) { return x.times.front() < y.times.front(); });
      curve.local_runs_ = std::move(all);
    }
  }

  // Where an unresolved window's fit, or a local stencil chosen without the motion's frequency,
  // gives a worse rate than one of the samples' local rates, that rate (docs/velocity.md, "Local
  // interpolant"); the segment's local runs are built again.
  if (!local_samples.empty() && curve.unresolved_windows() > 0) {
    std::vector<LocalRun> regression;
    for (const LocalRun& run : curve.local_runs_) {
      if (run.regression) regression.push_back(run);
    }
    bool changed = false;
    for (size_t k = 0; k + 1 < starts.size(); ++k) {
      changed = internal::ReviseLocalSamples(t, z, starts[k], starts[k + 1], curve.segments_[k], local_rates[k],
                                             window_rates, profile, regression, uncertain_level_dof,
                                             &local_samples[k]) ||
                changed;
    }
    if (changed) {
      std::vector<LocalRun> runs = std::move(regression);
      for (size_t k = 0; k + 1 < starts.size(); ++k) {
        std::vector<LocalRun> built = internal::BuildLocalRuns(t, z, starts[k], starts[k + 1], local_samples[k],
                                                               window_values, window_rates, profile);
        std::move(built.begin(), built.end(), std::back_inserter(runs));
      }
      std::sort(runs.begin(), runs.end(),
                [](const LocalRun& x, const LocalRun& y) { return x.times.front() < y.times.front(); });
      curve.local_runs_ = std::move(runs);
    }
  }

  ReportProgress(options.progress, "fitting windows", fitted_count, fitted_count);
  // Residuals at every sample fitted.
  Eigen::MatrixXd fitted;
  curve.EvaluateMany(stamps_ns, 0, &fitted);
  Eigen::VectorXd squares = Eigen::VectorXd::Zero(values.cols());
  for (Eigen::Index i = 0; i < m; ++i) {
    if (kept[static_cast<size_t>(i)]) squares += (fitted.row(order[i]) - values.row(order[i])).cwiseAbs2().transpose();
  }
  curve.residual_rms_ = (squares / static_cast<double>(fitted_count)).cwiseSqrt();
  return curve;
}

void Curve::Evaluate(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::VectorXd> derivative,
                     Eigen::Ref<Eigen::VectorXd> second_derivative, double tolerance_s) const {
  EvaluateUpTo(stamp_ns, 2, value, &derivative, &second_derivative, tolerance_s);
}

void Curve::EvaluateValue(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, double tolerance_s) const {
  EvaluateUpTo(stamp_ns, 0, value, nullptr, nullptr, tolerance_s);
}

void Curve::EvaluateVelocity(int64_t stamp_ns, Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::VectorXd> derivative,
                             double tolerance_s) const {
  EvaluateUpTo(stamp_ns, 1, value, &derivative, nullptr, tolerance_s);
}

Eigen::Index Curve::StepsBefore(double t) const {
  return std::upper_bound(step_times_.begin(), step_times_.end(), t) - step_times_.begin();
}

template <typename Row>
void Curve::AddSteps(double t, Row&& value) const {
  if (const Eigen::Index k = StepsBefore(t); k > 0) value += step_offsets_.row(k - 1);
}

const CurveSegment* Curve::FindSegment(double t, double tolerance_s) const {
  // The segment containing t (or nearest within the tolerance).
  const CurveSegment* segment = nullptr;
  for (const CurveSegment& s : segments_) {
    if (t >= s.begin - tolerance_s && t <= s.end + tolerance_s) {
      segment = &s;
      break;
    }
  }
  if (segment == nullptr) {
    // Between two segments split at a jump: the nearer one.
    for (size_t k = 0; k + 1 < segments_.size() && segment == nullptr; ++k) {
      const CurveSegment &left = segments_[k], &right = segments_[k + 1];
      if (left.continues && t > left.end && t < right.begin) segment = t - left.end <= right.begin - t ? &left : &right;
    }
  }
  return segment;
}

bool Curve::Covers(int64_t stamp_ns, double tolerance_s) const {
  return FindSegment(static_cast<double>(stamp_ns - origin_ns_) * 1e-9, tolerance_s) != nullptr;
}

Curve::Placement Curve::Locate(double t, double tolerance_s) const {
  const CurveSegment* segment = FindSegment(t, tolerance_s);
  if (segment == nullptr) {
    throw ComputeError(fmt::format("time {:.9f} s (from the first sample) is outside the fitted data or inside a gap",
                                   t));
  }
  const auto& windows = segment->windows;
  // The window whose core holds t.
  auto it = std::upper_bound(windows.begin(), windows.end(), t,
                             [](double time, const CurveWindow& w) { return time < w.core_begin; });
  const size_t k = it == windows.begin() ? 0 : static_cast<size_t>(it - windows.begin()) - 1;
  Placement placement;
  placement.left = &windows[k];
  // Blend with the neighbour across the nearest core boundary when t is in the blending zone.
  auto blend = [&](size_t left, size_t right) {
    const double boundary = windows[right].core_begin;
    // Half the overlap both windows have across the boundary: each is then well inside its data.
    const double half = 0.5 * std::min(windows[left].fit_end - boundary, boundary - windows[right].fit_begin);
    if (!(half > 0.0) || t < boundary - half || t > boundary + half) return false;
    placement.left = &windows[left];
    placement.right = &windows[right];
    Smoothstep((t - (boundary - half)) / (2.0 * half), &placement.s, &placement.ds, &placement.dds);
    placement.ds /= 2.0 * half;
    placement.dds /= 4.0 * half * half;
    return true;
  };
  if (!(k > 0 && blend(k - 1, k)) && k + 1 < windows.size()) blend(k, k + 1);
  return placement;
}

const LocalRun* Curve::LocalRunAt(double t) const {
  if (local_runs_.empty()) return nullptr;
  const auto it = std::upper_bound(local_runs_.begin(), local_runs_.end(), t,
                                   [](double time, const LocalRun& run) { return time < run.times.front(); });
  if (it == local_runs_.begin()) return nullptr;
  const LocalRun& run = *(it - 1);
  return t <= run.times.back() ? &run : nullptr;
}

namespace {

// The cubic Hermite interpolant of a local run at t (inside it): value, first and second derivative.
template <typename P, typename V, typename A>
void EvaluateLocal(const LocalRun& run, double t, int order, P&& p, V&& v, A&& a) {
  auto k = static_cast<Eigen::Index>(std::upper_bound(run.times.begin(), run.times.end(), t) - run.times.begin()) - 1;
  k = std::clamp<Eigen::Index>(k, 0, static_cast<Eigen::Index>(run.times.size()) - 2);
  const double t0 = run.times[static_cast<size_t>(k)], h = run.times[static_cast<size_t>(k) + 1] - t0;
  const double u = (t - t0) / h, u2 = u * u, u3 = u2 * u;
  const auto z0 = run.values.row(k), z1 = run.values.row(k + 1);
  const auto v0 = run.rates.row(k) * h, v1 = run.rates.row(k + 1) * h;
  p = (2 * u3 - 3 * u2 + 1) * z0 + (u3 - 2 * u2 + u) * v0 + (3 * u2 - 2 * u3) * z1 + (u3 - u2) * v1;
  if (order >= 1) v = ((6 * u2 - 6 * u) * z0 + (3 * u2 - 4 * u + 1) * v0 + (6 * u - 6 * u2) * z1 + (3 * u2 - 2 * u) * v1) / h;
  if (order >= 2) a = ((12 * u - 6) * z0 + (6 * u - 4) * v0 + (6 - 12 * u) * z1 + (6 * u - 2) * v1) / (h * h);
}

}  // namespace

void Curve::EvaluateUpTo(int64_t stamp_ns, int order, Eigen::Ref<Eigen::VectorXd> value,
                         Eigen::Ref<Eigen::VectorXd>* derivative, Eigen::Ref<Eigen::VectorXd>* second_derivative,
                         double tolerance_s) const {
  const double t = static_cast<double>(stamp_ns - origin_ns_) * 1e-9;
  Point p, v, a;
  if (const LocalRun* run = LocalRunAt(t)) {  // the run's, no window evaluated
    Eigen::RowVectorXd lp(dimension_), lv(dimension_), la(dimension_);
    EvaluateLocal(*run, t, order, lp, lv, la);
    p = lp.transpose(), v = lv.transpose(), a = la.transpose();
  } else {
    const Placement placement = Locate(t, tolerance_s);
    EvaluateWindow(*placement.left, t, order, &p, &v, &a);
    if (placement.right != nullptr) {
      // The blend's derivatives need both windows' values and lower derivatives.
      Point pr, vr, ar;
      EvaluateWindow(*placement.right, t, order, &pr, &vr, &ar);
      const double s = placement.s, ds = placement.ds, dds = placement.dds;
      if (order >= 2) a = (1.0 - s) * a + s * ar + 2.0 * ds * (vr - v) + dds * (pr - p);
      if (order >= 1) v = (1.0 - s) * v + s * vr + ds * (pr - p);
      p = (1.0 - s) * p + s * pr;
    }
  }
  value = p;
  AddSteps(t, value.transpose());
  if (order >= 1) *derivative = v;
  if (order >= 2) *second_derivative = a;
}

void Curve::EvaluateMany(std::span<const int64_t> stamps_ns, int order, Eigen::MatrixXd* values,
                         Eigen::MatrixXd* first, Eigen::MatrixXd* second, double tolerance_s) const {
  if (order < 0 || order > 2 || values == nullptr || (order >= 1 && first == nullptr) ||
      (order >= 2 && second == nullptr)) {
    throw std::invalid_argument("Curve::EvaluateMany: order 0..2 with an output for each derivative");
  }
  const auto n = static_cast<Eigen::Index>(stamps_ns.size());
  // Queries in time order, so that those a window serves are contiguous.
  std::vector<Eigen::Index> sorted(static_cast<size_t>(n));
  std::iota(sorted.begin(), sorted.end(), 0);
  if (!std::is_sorted(stamps_ns.begin(), stamps_ns.end())) {
    std::stable_sort(sorted.begin(), sorted.end(), [&](Eigen::Index i, Eigen::Index j) { return stamps_ns[i] < stamps_ns[j]; });
  }
  const Eigen::Index d = dimension_;
  values->resize(n, d);
  if (order >= 1) first->resize(n, d);
  if (order >= 2) second->resize(n, d);
  // The queries sorted[r0..r1) (each writes its own rows only), a block of at most
  // kEvaluationBlock at a time through the same scratch (about 150 bytes a query: the many
  // queries of a long recording at once took a third of its memory).
  auto evaluate = [&](Eigen::Index r0, Eigen::Index r1) {
    const Eigen::Index capacity = std::min(r1 - r0, kEvaluationBlock);
    std::vector<double> t(static_cast<size_t>(capacity));
    std::vector<Placement> placements(static_cast<size_t>(capacity));
    // A query inside a local run is the run's (no window is evaluated for it).
    std::vector<const LocalRun*> local(static_cast<size_t>(capacity));
    // Each window evaluated at a run of queries at once (vectorised Clenshaw), for the left and
    // the right window of every query: (order + 1) blocks of count x d each.
    std::array<Eigen::MatrixXd, 3> left, right;
    for (int k = 0; k <= order; ++k) {
      left[k].resize(capacity, d);
      right[k].resize(capacity, d);
    }
    for (Eigen::Index b0 = r0; b0 < r1; b0 += capacity) {
      const Eigen::Index count = std::min(capacity, r1 - b0);
      for (Eigen::Index r = 0; r < count; ++r) {
        t[r] = static_cast<double>(stamps_ns[sorted[b0 + r]] - origin_ns_) * 1e-9;
        local[r] = LocalRunAt(t[r]);
        placements[r] = local[r] == nullptr ? Locate(t[r], tolerance_s) : Placement{};
      }
      auto evaluate_runs = [&](bool use_right, std::array<Eigen::MatrixXd, 3>& out) {
        for (Eigen::Index begin = 0; begin < count;) {
          const CurveWindow* w = use_right ? placements[begin].right : placements[begin].left;
          Eigen::Index end = begin + 1;
          while (end < count && (use_right ? placements[end].right : placements[end].left) == w) ++end;
          if (w != nullptr) {
            const Eigen::Map<const Eigen::VectorXd> times(t.data() + begin, end - begin);
            for (int k = 0; k <= order; ++k) out[k].middleRows(begin, end - begin) = internal::WindowSeriesAt(*w, times, k);
          }
          begin = end;
        }
      };
      evaluate_runs(false, left);
      evaluate_runs(true, right);
      for (Eigen::Index r = 0; r < count; ++r) {
        const Placement& q = placements[r];
        const Eigen::Index i = sorted[b0 + r];
        if (local[r] != nullptr) {
          Eigen::RowVectorXd p(d), v(d), a(d);
          EvaluateLocal(*local[r], t[r], order, p, v, a);
          values->row(i) = p;
          AddSteps(t[r], values->row(i));
          if (order >= 1) first->row(i) = v;
          if (order >= 2) second->row(i) = a;
          continue;
        }
        if (q.right == nullptr) {
          values->row(i) = left[0].row(r);
          AddSteps(t[r], values->row(i));
          if (order >= 1) first->row(i) = left[1].row(r);
          if (order >= 2) second->row(i) = left[2].row(r);
          continue;
        }
        const double s = q.s, ds = q.ds, dds = q.dds;
        const auto dp = right[0].row(r) - left[0].row(r);
        values->row(i) = (1.0 - s) * left[0].row(r) + s * right[0].row(r);
        AddSteps(t[r], values->row(i));
        if (order >= 1) first->row(i) = (1.0 - s) * left[1].row(r) + s * right[1].row(r) + ds * dp;
        if (order >= 2) {
          second->row(i) = (1.0 - s) * left[2].row(r) + s * right[2].row(r) +
                           2.0 * ds * (right[1].row(r) - left[1].row(r)) + dds * dp;
        }
      }
    }
  };
  // Many queries are split into one contiguous part per thread: each query's numbers are the same
  // however they are split.
  const int parts = n >= kParallelQueries ? internal::ThreadCount(threads_) : 1;
  internal::ParallelRanges(n, parts, evaluate);
}

bool Curve::AtRounding(Eigen::Index c) const {
  return c >= 0 && c < rounding_.size() && internal::AtRoundingLevel(noise_sigma_[c], rounding_[c]);
}

Curve Curve::FromParts(int64_t origin_ns, std::vector<CurveSegment> segments, Eigen::VectorXd noise_sigma,
                       Eigen::VectorXd residual_rms) {
  if (segments.empty()) throw std::invalid_argument("Curve::FromParts: no segments");
  const Eigen::Index d = segments.front().windows.empty() ? 0 : segments.front().windows.front().series.dimension();
  if (d < 1 || d > 4) throw std::invalid_argument("Curve::FromParts: 1..4 coordinates");
  double previous_end = -std::numeric_limits<double>::infinity();
  for (CurveSegment& segment : segments) {
    if (segment.windows.empty() || !(segment.begin <= segment.end) || !(segment.begin > previous_end)) {
      throw std::invalid_argument("Curve::FromParts: segments must be non-empty, ordered and disjoint");
    }
    previous_end = segment.end;
    for (size_t k = 0; k < segment.windows.size(); ++k) {
      CurveWindow& w = segment.windows[k];
      const bool tiles = k == 0 ? w.core_begin <= segment.begin : w.core_begin == segment.windows[k - 1].core_end;
      if (w.series.dimension() != d || static_cast<Eigen::Index>(w.degrees.size()) != d || !tiles ||
          !(w.core_begin < w.core_end) || !(w.fit_begin <= w.core_begin) || !(w.fit_end >= w.core_end) ||
          !(w.series.interval.b > w.series.interval.a)) {
        throw std::invalid_argument("Curve::FromParts: windows must tile their segment with consistent series");
      }
      WindowFitter::Finish(&w);
    }
  }
  Curve curve;
  curve.origin_ns_ = origin_ns;
  curve.dimension_ = static_cast<int>(d);
  curve.segments_ = std::move(segments);
  curve.noise_sigma_ = std::move(noise_sigma);
  curve.residual_rms_ = std::move(residual_rms);
  curve.resolution_ = Eigen::VectorXd::Zero(d);
  curve.rounding_ = Eigen::VectorXd::Zero(d);
  curve.staircase_.assign(static_cast<size_t>(d), false);
  return curve;
}

Eigen::Index Curve::unresolved_windows() const {
  Eigen::Index count = 0;
  for (const CurveSegment& s : segments_) {
    for (const CurveWindow& w : s.windows) count += w.verdict == WindowVerdict::kUnresolved ? 1 : 0;
  }
  return count;
}

std::string_view ToString(WindowVerdict verdict) {
  switch (verdict) {
    case WindowVerdict::kResolved: return "resolved";
    case WindowVerdict::kUnresolved: return "unresolved";
    case WindowVerdict::kFixedDegree: return "fixed_degree";
    case WindowVerdict::kBridge: return "bridge";
  }
  return "unknown";
}

Eigen::Index Curve::local_samples() const {
  Eigen::Index count = 0;
  for (const LocalRun& run : local_runs_) count += run.regression ? 0 : static_cast<Eigen::Index>(run.times.size());
  return count;
}

Eigen::Index Curve::regression_samples() const {
  Eigen::Index count = 0;
  for (const LocalRun& run : local_runs_) count += run.regression ? static_cast<Eigen::Index>(run.times.size()) : 0;
  return count;
}

Eigen::Index Curve::stored_values() const {
  Eigen::Index total = (2 * dimension_ + 1) * (local_samples() + regression_samples());  // a time, values and rates
  for (const CurveSegment& s : segments_) {
    for (const CurveWindow& w : s.windows) {
      for (int degree : w.degrees) total += degree + 1;
    }
  }
  return total;
}

}  // namespace cheval::cheb

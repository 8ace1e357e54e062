#pragma once
// Internal to the cheb library: where a fitted segment could not resolve the motion, the curve
// follows the samples themselves (src/cheb/local_rates.cc; docs/velocity.md, "Local interpolant").

#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"
#include "cheval/cheb/fit.h"

namespace cheval::cheb::internal {

class NoiseProfile;

/// The window of each of a segment's n samples (from `first` in the sorted stamps `t`, s): the
/// last window whose core begins at or before the sample, the first window before that.
std::vector<Eigen::Index> SampleWindows(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n,
                                        const std::vector<CurveWindow>& windows);

/// The factor of the normal matrix, up to its highest degree, of `window`'s samples (in the sorted
/// stamps `t`, s, and values `z`), or none where it is singular (ComputeError) or has no degrees.
std::optional<NestedCholesky> FactorWindow(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const CurveWindow& window);

/// `window`'s values (order 0), rates (1) or second derivatives (2) at `times` (s), one row per time.
Eigen::MatrixXd WindowSeriesAt(const CurveWindow& window, const Eigen::Ref<const Eigen::VectorXd>& times, int order);

/// `scale`·T'_k(x) = `scale`·k·U_{k−1}(x) for k = 0 .. slopes.size() − 1: the Chebyshev polynomials'
/// derivatives at x in [−1, 1], by the U recurrence (`scale` the interval's DerivativeScale gives d/dt).
void ChebyshevSlopes(double x, double scale, Eigen::Ref<Eigen::VectorXd> slopes);

/// The variance factor dᵀG⁻¹d of the rate at time `at` (s) per coordinate, of fits on `interval` of
/// the given degrees whose normal matrix `cholesky` factors (d the derivative's basis there): times
/// σ², the rate's variance.
Eigen::VectorXd RateVarianceFactor(const NestedCholesky& cholesky, const Interval& interval, const std::vector<int>& degrees,
                                   double at);

/// The samples of a segment (n from `first` in the sorted stamps `t`) that a run spans, [from, to).
std::pair<Eigen::Index, Eigen::Index> SamplesOf(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n,
                                                const LocalRun& run);

/// Per window of a segment (rows) and coordinate (columns): the samples' local rate, 3 (the
/// derivative of the quadratic through a sample and its neighbours), 5 (of the quartic through it
/// and two neighbours on either side) or 9 (the slopes of the cubic spline through the samples),
/// and whether the samples under-resolve the motion, so that the local rate does better than the
/// window's fit wherever its residual says. Windows with fewer than 8 held-out samples keep 3 and
/// are not under-resolved.
struct LocalRates {
  Eigen::ArrayXXi stencil;
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> under_resolved;
  /// The slopes of the cubic spline through the segment's samples, clamped at the 3-point rates at
  /// its ends (n x d; empty where two stamps coincide).
  Eigen::MatrixXd spline_slopes;
  /// The 3-point rates at the segment's samples (n x d; empty with the spline's slopes).
  Eigen::MatrixXd three_rates;
  /// Whether the held-out errors fell with the order (the stencil was chosen knowing the motion's
  /// frequency), per window and coordinate.
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> modelled;
  /// Whether, at a segment's end sample, the quintic's one-sided rate through it and the next five
  /// errs less than the quadratic's through it and the next two, by the same model of noise and
  /// motion as the stencil, per window and coordinate.
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> one_sided_quintic;
};

/// The LocalRates of the windows of `segment`. Over the window's core, the held-out errors of the
/// polynomials of degree 3, 5 and 7 through 2, 3 and 4 neighbours on either side fall by
/// u·(6/20)² and u·(20/70)² from each order to the next for motion of frequency ω,
/// u = (2 sin(ωh/2))², which gives ω (white noise keeps them level; the degree-7 error bounds the
/// noise). The stencil is the rate whose error by that model, its noise plus its bias at ω, is
/// least; where that is the 3-point rate, the spline's slopes replace it when the mean squared
/// difference between the two exceeds 1.177·σ²/h² (σ the noise profile's over the window): the model
/// reads a spread spectrum near a quarter of the rate as noise, and σ too can only make this test
/// stricter. The samples under-resolve the motion (this needs no σ) when both falls are by more
/// than half, ω lies above the 2N/span the window resolves, and the rate error of the missed
/// motion, ω² times the window's generalised cross-validation error less its noise, exceeds the
/// model's least. docs/velocity.md, "Local interpolant".
LocalRates UnderResolvedRates(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                              Eigen::Index last, const CurveSegment& segment, const NoiseProfile& noise);

/// Per sample of a segment (rows) and coordinate (columns): whether the curve follows the sample
/// there (`local`), whether its rate is then the 5-point one (`five`) or the spline's slopes
/// (`spline`) instead of the 3-point one, and whether that stencil was chosen knowing the motion's
/// frequency (`modelled`: the held-out errors' orders fell, LocalRates::modelled; only where
/// `local`).
struct LocalSamples {
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> local, five, spline, modelled;
};

/// The local samples of one segment. A sample is local in coordinate c when it lies in the core of
/// a window accepted unresolved
/// - whose residual in c is clearly above the noise: the lack-of-fit score above its limit and the
///   residual's variance on its degrees of freedom, RSS/(m − N − 1), at least 2σ² (the missed
///   motion is at least as large as the noise, so the samples' own local derivative, whose noise
///   is σ/(sqrt(2)·h), is the better estimate);
/// - or whose rate departs from the spline's slopes (`rates.spline_slopes`) by more than the
///   spline's noise allows: over the window and two on either side, the mean (r_s − r_fit)² above
///   twice the spline's noise, 1.392·σ²/h² (the break-even: r_s − r_fit holds the spline's noise
///   and the window's bias, and the spline's bias is small, so the window's bias exceeds the
///   spline's noise), where the window's missed motion could hold that bias: its generalised
///   cross-validation error less the noise's share, times (π/h)² (a component of the positions
///   below the sampling rate's Nyquist frequency errs in rate by at most that), reaches the mean
///   departure less the spline's noise. Motion near a quarter of the rate that no window resolves
///   lies mostly below the noise in each window's residual; in its rate it is clear;
/// - or of a window whose samples under-resolve the motion (`rates`).
///
/// `t` (sorted, s) is the curve's fitted samples' stamps, [first, last) the segment's, `rates` its
/// UnderResolvedRates, `fit_rates` (m x d) the segment's fit at them, `noise` the curve's noise
/// profile (σ per window: its RMS over the window's core).
LocalSamples ChooseLocalSamples(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index last,
                                const CurveSegment& segment, const LocalRates& rates, const Eigen::MatrixXd& fit_rates,
                                const NoiseProfile& noise, double lack_of_fit_limit);

/// The local runs of one segment's `chosen` samples. A run is a maximal stretch of consecutive
/// samples local in some coordinate, with one sample of the fit on either side inside the segment
/// (its value and derivative are the fit's: the curve stays C¹ where it passes from the fit to
/// the samples).
///
/// The rate at a local sample is the stencil chosen for it: the derivative of the quadratic
/// through it and its two neighbours (one-sided at the segment's ends), of the quartic through it
/// and two neighbours on either side, or the clamped cubic spline's slopes over stretches, from
/// slopes between consecutive samples that are neither over a close step (shorter than half the
/// shorter step beside it, whose rate would carry the pair's noise over it; the sample beside one
/// takes the quadratic through its other neighbour and the sample past its partner) nor isolated
/// spikes: a slope whose departure from
/// the mean of its two neighbours is above 4 local scales (1.4826·median departure over 64 slopes,
/// floored at the noise's sqrt(5)·σ/h), larger than its neighbours' and opposed by both (a step of
/// the values moves the neighbours' departures the other way, smooth curvature moves them
/// together) is a small step of the values the jump search left (a correction of filtered ground
/// truth) and is not used.
///
/// `t` (sorted, s) and `z` (m x d, steps taken out) are the curve's fitted samples, [first, last)
/// the segment's, `fit_values` and `fit_rates` (m x d) the segment's fit at them, `noise` the
/// curve's noise profile.
std::vector<LocalRun> BuildLocalRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                     Eigen::Index last, const LocalSamples& chosen, const Eigen::MatrixXd& fit_values,
                                     const Eigen::MatrixXd& fit_rates, const NoiseProfile& noise);

/// The weights on the samples of the local rate `chosen` gives sample i of a segment (n samples
/// from `first` in the sorted stamps `t`) in coordinate c — the 3-point rate's, the 5-point one's or
/// the spline's slopes' — and the segment's sample the first weight is on. The substitutions beside
/// close steps and spikes (BuildLocalRuns) are not followed: the weights serve to compare the
/// noise of rates, to which a few such samples add little.
std::pair<Eigen::Index, Eigen::VectorXd> LocalRateWeights(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index n,
                                                          const LocalSamples& chosen, Eigen::Index i, Eigen::Index c);

/// Per coordinate, whether the local interpolant's samples of a segment (n samples from `first` in
/// the sorted stamps `t` and values `z`) carry mostly noise: over them, the mean squared difference
/// of the 3-point and 5-point rates is at most twice the noise the two share, σ²·|w₃ − w₅|² (σ
/// the noise profile's). Where it is more, their biases differ: the samples' rates carry motion
/// (as a filter's output does, sample to sample) that a smoother would take away.
std::vector<char> NoisyLocalSamples(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index n,
                                    const LocalSamples& chosen, const NoiseProfile& noise);

/// Revises a segment's `chosen` local samples after the local regression (`regression`: its runs,
/// whose samples it leaves). Per unresolved window and coordinate, pooled with kPooledGainWindows
/// windows on either side, the spline's slopes serve as a reference of little bias: each candidate
/// rate's error (the 3-point, the 5-point, the spline's) is estimated from its mean squared
/// departure from them and the noise the two share (from their weights on the stamps), and the
/// samples' present rate (the windows' fit, with its rate noise counted; or a local stencil the
/// held-out errors' model chose without knowing the motion's frequency) gives way to the candidate
/// of least error where its gain stands out by two standard errors of the windows' scatter.
/// Nothing changes where the 5-point rate departs from the spline's slopes by more than
/// kReferenceNoise times its noise (the biases, the spline's too, would decide), at samples beside
/// close steps, nor at the fit's samples where the window's missed motion cannot hold their
/// departure. Where the noise dominates motion near a quarter of the rate, windows of ~20 samples
/// miss much of it and pass their residual test with σ read high (docs/velocity.md, "Local
/// interpolant"). `level_dof` > 0: the noise level is an estimate with that many degrees of freedom
/// (a short recording), and a gain must hold with σ² raised by two of its standard deviations,
/// sqrt(2/level_dof), where σ² counts against the change. Returns whether any sample changed.
bool ReviseLocalSamples(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first, Eigen::Index last,
                        const CurveSegment& segment, const LocalRates& rates, const Eigen::MatrixXd& fit_rates,
                        const NoiseProfile& noise, const std::vector<LocalRun>& regression, double level_dof,
                        LocalSamples* chosen);

}  // namespace cheval::cheb::internal

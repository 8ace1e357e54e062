#pragma once
// Internal to the cheb library: where windows were split for missed motion, a local polynomial
// regression may take over the rate (src/cheb/local_regression.cc; docs/velocity.md, "Local
// regression").

#include <vector>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"
#include "local_rates.h"

namespace cheval::cheb::internal {

class NoiseProfile;

/// Whether the local regression is tried in a window's core: the window was split for missed
/// motion, or it spends a coefficient on fewer samples than the widest candidate (53) spans, so
/// its rate is as local as theirs. A window with more samples per coefficient is smoother than
/// any candidate and has resolved the motion (it passed the residual and coefficient tests), and
/// scoring its stretch would cost ~0.2 s of CPU on a 100k-sample drone flight for nothing.
bool RegressionMayGain(const CurveWindow& window);

/// The local-regression runs of one segment. Candidates are stretches of consecutive samples in
/// the cores of windows where RegressionMayGain, the segment's first and last window left out (the
/// end caps' variance is not the window's). Per stretch and coordinate, each local polynomial
/// regression of odd degree 1–7 over 7–53 samples centred on each sample (shifted to stay inside
/// the segment) is scored by its velocity error estimated against a pilot of little bias (degree 7
/// over 15 samples), mean (v_a − v_P)² + 2σ²·w_a·w_P (w the rate's weights on the samples; the
/// pilot's own σ²|w_P|² is common to every candidate and cancels), and so is the present rate (the
/// windows', with their weights from each core window's normal matrix, or at the local
/// interpolant's samples its stencil's, LocalRateWeights). The best candidate replaces the present
/// rate in that coordinate when its score, plus twice the pilot's squared bias (estimated against
/// degree 7 over 11 samples, less 2 standard errors of that estimate from the means of 53-sample
/// blocks), is below the present rate's — where that bias alone keeps the best candidate out
/// (motion near a quarter of the rate, which a 15-sample pilot misses whole), the coordinate is
/// scored again against the 9-point stencil's rate, its bias judged against the 7-point one's —,
/// its gain is at least 2 standard errors (from the means of 53-sample blocks; stretches of at
/// least 4 blocks), and the present rates differ from the pilot's by at least a quarter of what σ
/// implies (else σ overstates the noise and they are kept; σ² itself is the smaller of the data's
/// and what those differences imply). A run carries the regression's value and rate at the
/// samples of the coordinates it replaces, the present curve's elsewhere, and starts and ends on
/// a sample of the windows' fit (the local interpolant's samples inside it are to be taken out of
/// its runs).
///
/// `t` (sorted, s) and `z` (m x d, steps taken out) are the curve's fitted samples, [first, last)
/// the segment's, `window_values` and `window_rates` (m x d) the windows' fit at them,
/// `fit_values` and `fit_rates` the present curve's (the local interpolant's where it took over),
/// `local` the segment's local samples (none: the windows' fit throughout), `noise` the curve's
/// noise profile (σ per stretch: its RMS over the stretch), `rounding` per coordinate q/sqrt(12) of
/// rounded values (0: not rounded), `staircase` whether a coordinate was placed between its steps
/// (Curve::Staircase). A coordinate whose σ over a stretch is the rounding's keeps its rate there:
/// its errors form a staircase, which the scores, made for white noise, would follow; so does a
/// staircase placed between its steps everywhere, whose errors run smoothly from crossing to
/// crossing (tones rounded to 1 mm at 1000 Hz: 3.3 → 15.3 mm/s on one axis).
std::vector<LocalRun> LocalRegressionRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                          Eigen::Index last, const CurveSegment& segment,
                                          const Eigen::MatrixXd& window_values, const Eigen::MatrixXd& window_rates,
                                          const Eigen::MatrixXd& fit_values, const Eigen::MatrixXd& fit_rates,
                                          const LocalSamples* local, const NoiseProfile& noise,
                                          const Eigen::VectorXd& rounding, const std::vector<bool>& staircase);

}  // namespace cheval::cheb::internal

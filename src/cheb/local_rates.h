#pragma once
// Internal to the cheb library: where a fitted segment could not resolve the motion, the curve
// follows the samples themselves (src/cheb/local_rates.cc; docs/velocity.md, "Local interpolant").

#include <vector>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"

namespace cheval::cheb::internal {

/// The local runs of one segment. A sample is local in coordinate c when it lies in the core of
/// a window accepted unresolved whose residual in c is clearly above the noise (the lack-of-fit
/// score above its limit and the residual RMS at least sqrt(2)·σ: the missed motion is at least as
/// large as the noise, so the samples' own local derivative, whose noise is σ/(sqrt(2)·h), is the
/// better estimate). A run is a maximal stretch of consecutive samples local in some coordinate,
/// with one sample of the fit on either side inside the segment (its value and derivative are the
/// fit's: the curve stays C¹ where it passes from the fit to the samples).
///
/// The rate at a local sample is the derivative of the quadratic through it and its two
/// neighbours (one-sided at the segment's ends), from slopes between consecutive samples that are
/// not isolated spikes: a slope whose departure from the mean of its two neighbours is above 4
/// local scales (1.4826·median departure over 64 slopes, floored at the noise's sqrt(5)·σ/h) and
/// larger than its neighbours' is a small step of the values the jump search left (a correction of
/// filtered ground truth) and is not used.
///
/// `t` (sorted, s) and `z` (m x d, steps taken out) are the curve's fitted samples, [first, last)
/// the segment's, `fit_values` and `fit_rates` (m x d) the segment's fit at them, `sigma` the
/// noise per coordinate.
std::vector<LocalRun> LocalRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                Eigen::Index last, const CurveSegment& segment, const Eigen::MatrixXd& fit_values,
                                const Eigen::MatrixXd& fit_rates, const Eigen::VectorXd& sigma, double lack_of_fit_limit);

}  // namespace cheval::cheb::internal

#pragma once
// Internal to the cheb library: where a fitted segment could not resolve the motion, the curve
// follows the samples themselves (src/cheb/local_rates.cc; docs/velocity.md, "Local interpolant").

#include <vector>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"

namespace cheval::cheb::internal {

/// Per window of `segment` (rows) and coordinate (columns), where the samples under-resolve the
/// motion: the local rate that does better than the window's fit, 3 (the derivative of the
/// quadratic through a sample and its neighbours), 5 (of the quartic through it and two
/// neighbours on either side) or 9 (the slopes of the cubic spline through the samples), else 0. Needs no σ (the noise estimate reads such motion as noise).
/// Over the window's core, the held-out errors of the polynomials of degree 3, 5 and 7 through 2,
/// 3 and 4 neighbours on either side must fall by more than half from each order to the next
/// (white noise keeps them level; motion of frequency ω lowers each by u·(6/20)² and u·(20/70)²,
/// u = (2 sin(ωh/2))², which gives ω); ω must lie above the 2N/span the window resolves; and the
/// rate error of the missed motion, ω² times the window's generalised cross-validation error less
/// its noise, must exceed the local rate's, its noise plus its bias at ω (the degree-7 error bounds
/// the noise). docs/velocity.md, "Local interpolant". Windows with fewer than 8 held-out samples
/// are left alone.
Eigen::ArrayXXi UnderResolvedRates(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                   Eigen::Index last, const CurveSegment& segment);

/// The local runs of one segment. A sample is local in coordinate c when it lies in the core of
/// a window accepted unresolved whose residual in c is clearly above the noise (the lack-of-fit
/// score above its limit and the residual RMS at least sqrt(2)·σ: the missed motion is at least as
/// large as the noise, so the samples' own local derivative, whose noise is σ/(sqrt(2)·h), is the
/// better estimate), or of a window where UnderResolvedRates finds a local rate. A run is a maximal stretch of consecutive samples local in some coordinate,
/// with one sample of the fit on either side inside the segment (its value and derivative are the
/// fit's: the curve stays C¹ where it passes from the fit to the samples).
///
/// The rate at a local sample is the derivative of the quadratic through it and its two
/// neighbours (one-sided at the segment's ends; of the quartic through it and two neighbours on
/// either side where UnderResolvedRates chose 5; the clamped cubic spline's slopes over stretches
/// where it chose 9), from slopes between consecutive samples that are
/// not isolated spikes: a slope whose departure from the mean of its two neighbours is above 4
/// local scales (1.4826·median departure over 64 slopes, floored at the noise's sqrt(5)·σ/h) and
/// larger than its neighbours' is a small step of the values the jump search left (a correction of
/// filtered ground truth) and is not used.
///
/// `t` (sorted, s) and `z` (m x d, steps taken out) are the curve's fitted samples, [first, last)
/// the segment's, `under_resolved` its UnderResolvedRates, `fit_values` and `fit_rates` (m x d)
/// the segment's fit at them, `sigma` the noise per coordinate.
std::vector<LocalRun> LocalRuns(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, Eigen::Index first,
                                Eigen::Index last, const CurveSegment& segment, const Eigen::ArrayXXi& under_resolved,
                                const Eigen::MatrixXd& fit_values, const Eigen::MatrixXd& fit_rates,
                                const Eigen::VectorXd& sigma, double lack_of_fit_limit);

}  // namespace cheval::cheb::internal

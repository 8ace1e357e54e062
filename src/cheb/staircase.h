#pragma once
// Internal to the cheb library: values rounded to a lattice that move less than a step a sample
// (a staircase), placed between their steps (docs/velocity.md, "Rounded positions").

#include <optional>
#include <vector>

#include <Eigen/Core>

namespace cheval::cheb::internal {

/// Where a coordinate's values, rounded to steps of q, form a clean staircase, replaces each value
/// by a curve through the instants the values cross from one step to the next, kept within its
/// own step, and returns the noise σ of the values placed: the RMS error with which each crossing
/// is predicted by the cubic through its two neighbours on either side, scaled to one crossing's.
/// nullopt (and the values untouched) where the values are no such staircase, or where that σ is
/// not below half the rounding's q/sqrt(12).
///
/// A value rounded to the step k·q says only that the motion lies within q/2 of it; the sample
/// interval in which it passes from step k to k + 1 says that it crossed (k + 1/2)·q there, to
/// within the motion in half an interval. On slow motion written to a coarse step (a millimetre at
/// 1000 Hz: ~30 samples a step) those crossings fix the motion to a few percent of the step, where
/// the rounded values err by q/sqrt(12) with errors correlated over a whole step.
///
/// `t` ascending; `z` the values on the lattice of step q from FindResolution and `steps` the same
/// in whole steps (WholeSteps(z, q)); `breaks` the boundaries b (between samples b and b + 1) no
/// curve is drawn across (gaps). Only a clean staircase qualifies: at least 75 % of the
/// differences zero (a step lasts four samples or more on average), nearly all others one step,
/// and few of them undone by the next, very few within a few samples (noise at a step's edge flips
/// the values back and forth, and the instants of those flips are the noise's).
std::optional<double> PlaceBetweenSteps(const Eigen::Ref<const Eigen::VectorXd>& t, Eigen::Ref<Eigen::VectorXd> z,
                                        const Eigen::VectorXd& steps, double q,
                                        const std::vector<Eigen::Index>& breaks);

}  // namespace cheval::cheb::internal

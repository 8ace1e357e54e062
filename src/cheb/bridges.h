#pragma once
// Internal to the cheb library: fits across the gaps between segments (src/cheb/bridges.cc).

#include <vector>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"
#include "noise_profile.h"

namespace cheval::cheb::internal {

/// Lets a fit across a gap take over the ends of the segments beside it, where the data on both
/// sides say it is the better estimate (docs/velocity.md, "Gaps").
///
/// A gap splits the data into segments fitted apart, and the samples next to it are a segment's
/// end, whose rate a one-sided fit gives with a variance growing like N⁴/m: under noise, a
/// recording with many dropouts is mostly such ends. Across a gap of length g the samples within
/// 2g, 4g, 8g, 16g or 32g on either side (at least 4 on each; across further gaps, not across a
/// jump) are fitted by one polynomial of degree at most (π/2)·span/h, h the longest hole inside
/// (what it allows: WindowFitter::TopDegree), N²/m ≤ 8 and m/2 − 1, chosen per coordinate by
/// generalised cross-validation; its residual must pass the residual test, and of the reaches that
/// pass, the one whose rates beside the gap have the least variance is kept. A side of it then
/// stands in for the segment's end where
///   1. its rate at the sample beside the gap has the smaller variance (σ²·dᵀG⁻¹d, d the
///      derivative's basis) than the segment's own end window's there, and
///   2. its residuals where it takes over show no trend (ResidualTrendIsNoise): under noise their
///      slope is the noise's; on nearly noise-free data it is the bias of a fit held to a hole's
///      low degree, where the segment's own end is exact.
/// A segment that the fits of its gaps cover whole (a short one between dropouts) is replaced by
/// one that helps over all of it (with the smaller variance at both its ends); where both do, by
/// the one whose rate has the smaller variance at the segment's two ends. Otherwise a side becomes
/// the segment's last (or first) window, re-expanded exactly on the segment's samples it covers, as
/// an end cap does: alone over the z/2 samples next to the gap and blended into the segment's
/// windows up to 1.5z, z a third of its samples within reach (and of the segment's). Its verdict is
/// WindowVerdict::kBridge.
///
/// `t` (sorted, s) and `z` are the curve's samples, `starts` the segments' first samples followed
/// by the sample count, `segments` their fits (ends capped; a segment that `continues` ends at a
/// jump, not a gap), `noise` the samples' noise profile and `sigma_floor` the floor of their noise σ
/// per coordinate (the values' rounding level). The gaps are fitted on up to `threads` threads.
void BridgeGaps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const std::vector<Eigen::Index>& starts,
                const NoiseProfile& noise, const Eigen::VectorXd& sigma_floor, std::vector<CurveSegment>* segments,
                int threads = 1);

/// A floor under the residual sums of squares of every least-squares fit of `z` (m x d) of degree
/// at most `top` on the same samples, per coordinate, from the top degree's `top_squares`: the fits
/// are nested, so none leaves less. It lies 1e-4 of it below, for the rounding of residuals
/// evaluated on the samples; 0 where that rounding could reach 1 % of that margin (nearly exact
/// data, or values large against their residual). Generalised cross-validation across a gap skips
/// the degrees whose score could not beat the best at that floor.
Eigen::VectorXd NestedResidualFloor(const Eigen::Ref<const Eigen::MatrixXd>& z, const Eigen::VectorXd& top_squares,
                                    int top);

}  // namespace cheval::cheb::internal

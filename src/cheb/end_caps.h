#pragma once
// Internal to the cheb library: the end caps of a fitted curve segment (src/cheb/end_caps.cc).

#include <functional>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"

namespace cheval::cheb::internal {

/// The fitted curve's velocity (count x d) at the sorted samples first .. first + count - 1.
using VelocityAt = std::function<Eigen::MatrixXd(Eigen::Index first, Eigen::Index count)>;

/// Replaces the velocity of a segment's fit near its two ends by short, low-degree "caps" where
/// that is estimated to lower the velocity error (docs/velocity.md, "End caps").
///
/// The derivative of a least-squares polynomial is worst at the ends of its interval (its variance
/// grows like N⁴/m there), and nothing inside one end window can tell how much worse: the data
/// beyond the end are missing. So the choice is made where the answer can be checked: at many
/// artificial ends inside the segment. Each candidate cap (m samples, degree p) and the segment's
/// own end-window configuration are fitted one-sidedly at 32 positions in each direction inside
/// the segment's interior, and their velocities are compared with the curve's interior velocity
/// there (whose error is several times smaller than any one-sided fit's). The pooled squared
/// errors, with the same C² blend the curve applies, pick the cap length, the blending boundary and
/// a degree per coordinate; a coordinate for which no cap is estimated to help keeps the end
/// window's own polynomial inside the cap. A cap is added only when it lowers the pooled error.
///
/// A segment of one or two windows has no interior off its end windows, and one whose end windows
/// overlap may leave too little there to judge the candidates (room for fewer than 8 one-sided fits
/// of their length). With `short_segments`, such an end's artificial ends then lie in the middle
/// half of its end window's samples, where that
/// window's rate is the reference (its variance there is a fraction of the end's); the window's own
/// error at the real end, which no artificial end reproduces, is taken as its rate's variance there
/// (σ²·dᵀG⁻¹d with the window's σ, without a bias), and a cap is added where the blend of the two
/// errors (bounded by Cauchy–Schwarz, as they are not independent) is estimated to be smaller.
///
/// `t` (sorted, s) and `z` (m x d) are the curve's samples, `velocity` gives the fitted curve's
/// velocity at them (asked only where the artificial ends need it), [first, last) the segment's
/// samples; `front_at_jump` says the segment starts at a jump (its end at one: `continues`), where
/// no cap shorter than 16 samples is tried. The cap becomes the segment's first (or last) window;
/// the neighbouring end window's core is shortened to make room. Segments too short for artificial
/// ends are left as they are. The two ends' caps are chosen on up to `threads` threads (`velocity`
/// is then called concurrently).
void AddEndCaps(const Eigen::VectorXd& t, const Eigen::MatrixXd& z, const VelocityAt& velocity, Eigen::Index first,
                Eigen::Index last, bool front_at_jump, bool short_segments, CurveSegment* segment, int threads = 1);

}  // namespace cheval::cheb::internal

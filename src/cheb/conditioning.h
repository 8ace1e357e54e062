#pragma once
// Internal to the cheb library: the conditioning limit shared by the automatic fit (curve.cc) and
// the tolerance fit (compress.cc).

namespace cheval::cheb::internal {

/// Largest condition number of a window's normal matrix accepted: 1e10 keeps its coefficients
/// accurate to ~1e-6 relative, far below any noise plateau the chop looks for. Uneven sampling
/// (holes inside a window) is what drives it up at a given N²/m (docs/velocity.md, "Formulas").
inline constexpr double kMaxGramCondition = 1e10;

}  // namespace cheval::cheb::internal

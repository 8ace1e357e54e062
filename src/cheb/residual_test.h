#pragma once
// Internal to the cheb library: the residual test of a fitted window (curve.cc) and of a fit across
// a gap (bridges.cc), docs/velocity.md "Residual test".

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "cheval/cheb/curve.h"

namespace cheval::cheb::internal {

// A window's residual is consistent with the noise while its lack-of-fit score (a standard normal
// score of χ²) stays below cheb::kLackOfFitLimit = 3 (curve.h): a false alarm per coordinate and
// window has probability 0.13 % (a split that costs little), while at 4 small unresolved motion (a
// tremor of twice the noise) passes in short windows (docs/decisions.md).
using cheb::kLackOfFitLimit;
// The residual is tested against the noise σ times this: σ is an estimate and the noise of real
// data (and of rotation charts, J_r⁻¹ stretched) varies by some per cent, which in a window of
// hundreds of samples a χ² test alone would take for unresolved motion (it made the drone's body
// rate 2–3x worse); a residual of 1.5σ (a missed tremor) still fails.
inline constexpr double kNoiseMargin = 1.1;

// The rounding level of one coordinate's values `z`: 1e-9 of their range, at least 1e-9 (values
// written to nanometres), and a few units in the last place of the largest (the doubles' own
// spacing). Not of their magnitude: positions far from the origin (UTM northings, 5e6 m) raised it
// to millimetres, which blinded the residual test and the jump search there (EuRoC MH_05 moved to
// UTM coordinates: 1.20 -> 1.48 mm/s against its own velocity).
inline double RoundingFloor(const Eigen::Ref<const Eigen::VectorXd>& z) {
  if (z.size() == 0) return 1e-9;
  const double range = z.maxCoeff() - z.minCoeff();
  return 1e-9 * (1.0 + range) + 4.0 * std::numeric_limits<double>::epsilon() * z.cwiseAbs().maxCoeff();
}

// The noise σ per coordinate a window's samples `z` are tested against: the noise profile's over
// them (`level`), floored at the values' rounding level (RoundingFloor) so that exact data do not
// ask for an exact fit. Not the window's own estimate: a short window's scatters by tens of per
// cent, and taking the larger would let small unresolved motion pass as noise; the profile pools
// 160 samples and departs from the data's level only by a factor that scatter does not reach
// (NoiseProfile). With `floor`, that rounding level per coordinate too.
inline Eigen::VectorXd WindowSigma(const Eigen::VectorXd& level, const Eigen::Ref<const Eigen::MatrixXd>& z,
                                   Eigen::VectorXd* floor = nullptr) {
  Eigen::VectorXd sigma(z.cols());
  if (floor != nullptr) floor->resize(z.cols());
  for (Eigen::Index c = 0; c < z.cols(); ++c) {
    const double rounding = RoundingFloor(z.col(c));
    sigma[c] = std::max(level[c], rounding);
    if (floor != nullptr) (*floor)[c] = rounding;
  }
  return sigma;
}

// Standard normal score of RSS/σ² against χ² with `dof` degrees of freedom (Wilson–Hilferty:
// (X/ν)^(1/3) is nearly normal with mean 1 − 2/(9ν) and variance 2/(9ν)); 0 without freedom.
// With `sigma_dof` > 0, σ² is itself an estimate with that many degrees of freedom, and the
// score is that of RSS/(νσ²) against F(ν, sigma_dof) (Paulson's approximation, which reduces to
// Wilson–Hilferty as sigma_dof grows: Abramowitz & Stegun 26.6.15).
inline double LackOfFitScore(double rss, double sigma, Eigen::Index dof, double sigma_dof = 0.0) {
  if (dof <= 0) return 0.0;
  sigma *= kNoiseMargin;
  const double nu = static_cast<double>(dof), v = 2.0 / (9.0 * nu);
  const double root = std::cbrt(rss / (sigma * sigma) / nu);
  if (sigma_dof <= 0.0) return (root - (1.0 - v)) / std::sqrt(v);
  const double w = 2.0 / (9.0 * sigma_dof);
  return ((1.0 - w) * root - (1.0 - v)) / std::sqrt(w * root * root + v);
}

}  // namespace cheval::cheb::internal

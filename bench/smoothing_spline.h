#pragma once
// A baseline for bench/velocity_accuracy.cc: the cubic smoothing spline of each coordinate with its
// smoothing parameter chosen by generalised cross-validation (GCV), differentiated at the samples.
// Reinsch's algorithm (Green & Silverman, "Nonparametric Regression and Generalized Linear Models",
// 1994, §2.3) and the banded elements of the inverse for the hat matrix's trace (Hutchinson & de Hoog,
// "Smoothing noisy data with spline functions", Numer. Math. 47, 1985). Bench code, not the library.

#include <cstdint>
#include <span>

#include <Eigen/Core>

namespace cheval::bench {

/// Per coordinate, the natural cubic smoothing spline minimising Σ (y_i − f(t_i))² + λ ∫ f''² with λ
/// the minimiser of GCV(λ) = n·RSS / (n − tr A(λ))², and its derivative at every stamp. Stamps must
/// strictly increase; at least 4 samples.
Eigen::Matrix3Xd SmoothingSplineVelocity(std::span<const int64_t> stamps_ns, const Eigen::Matrix3Xd& positions);

}  // namespace cheval::bench

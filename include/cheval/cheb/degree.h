#pragma once
/// \file
/// Choosing the degree of a least-squares Chebyshev fit automatically, and estimating the noise
/// level of the samples that sets the threshold.

#include <Eigen/Core>

namespace cheval::cheb {

/// Chebfun's `standardChop` (Aurentz & Trefethen, *Chopping a Chebyshev series*, ACM TOMS 2017):
/// given coefficients c_0..c_{n-1} (absolute values are used) and a relative tolerance `tol` in
/// (0, 1), returns how many leading coefficients to keep (the chosen degree plus one), or n when
/// the series has not reached a plateau at the tolerance (not resolved). Needs n >= 17: for
/// shorter series it returns n.
int StandardChop(const Eigen::Ref<const Eigen::VectorXd>& coefficients, double tol);

/// Estimates the standard deviation of white noise on samples of a smooth signal from the k-th
/// order differences of consecutive samples: for white noise, Var(Δ^k z) = C(2k, k)·σ², while the
/// differences of an oversampled smooth signal are negligible. Robust: uses the median absolute
/// difference (× 1.4826). `z` is m x d (each column a coordinate); returns one σ per column.
/// Returns zeros when m <= k.
Eigen::VectorXd EstimateNoiseSigma(const Eigen::Ref<const Eigen::MatrixXd>& z, int order = 4);

}  // namespace cheval::cheb

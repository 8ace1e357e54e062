#pragma once
/// \file
/// Choosing the degree of a least-squares Chebyshev fit automatically, and estimating the noise
/// level of the samples that sets the threshold.

#include <vector>

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

/// The same estimate for samples at times `t` (sorted, m), evenly spaced or not: each run of five
/// consecutive samples gives the 4th divided difference Σ w_j z_j, w_j = 1/Π_{k≠j}(t_j − t_k),
/// which annihilates cubics whatever the spacing, and Σ w_j z_j / sqrt(Σ w_j²) has standard
/// deviation σ under white noise. σ̂ = 1.4826 · median of its magnitude; over fewer than 300
/// samples, where the median scatters by more than 10 %, Huber's winsorized scale (the s with
/// mean(min(x², 4s²)) = 0.774·s², from the median's value; docs/velocity.md, "Noise estimate"),
/// which scatters by a quarter less, wherever it agrees with the median's as white noise's do (in
/// heavier tails lies motion). For even spacing and 300 samples or more this is
/// exactly the 4th-difference estimate above; with stamp jitter or uneven sampling that one
/// mistakes the spacing for noise (a velocity v and a jitter δt look like noise v·δt). Runs with
/// two equal stamps, and runs that cross a boundary in `breaks` (a run may not contain both
/// samples i and i + 1 for a listed i), are skipped.
///
/// Motion in the upper part of the band also reaches the 4th differences (by (2 sin(ωh/2))⁴, where
/// noise gains 70): the same estimate from the 6th and then the 8th divided differences (7 and 9
/// samples), which white noise leaves at σ while such motion falls by (2 sin(ωh/2))² per order,
/// replaces it (the lower of the two when both do) where it is below the 4th's by more than six
/// standard deviations of white noise's scatter between the orders (0.67/sqrt(m) for the 6th,
/// 0.90/sqrt(m) for the 8th, m samples), and wherever it is below 0.8 of it. At a twelfth of the
/// sampling rate, noise-free motion read as 25 µm of noise by the 4th differences reads as 0.3 µm;
/// at a quarter, 0.5 mm of noise read as 0.65 mm reads as 0.54 mm.
Eigen::VectorXd EstimateNoiseSigma(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                                   const std::vector<Eigen::Index>& breaks = {});

}  // namespace cheval::cheb

#pragma once
// The quadrotor estimator's prior on the collective rotor speed (QuadrotorEstimateOptions::thrust_prior;
// docs/estimator.md, "The algorithm", step 5), built from the pilot solution. Implementation header of
// src/estim (not installed).

#include "cheval/estim/models.h"
#include "cheval/estim/problem.h"

namespace cheval::estim {

/// Adds, through problem.AddPrior, per world axis a, a Matérn-3/2 process on the thrust acceleration
/// a = (k_F ΣΩ²/m) R e3 − ḡ (ḡ = (0, 0, |g|)): ∫ |(D + λ_a)² a_a|² dt / σ_s² per segment
/// (internal/thrust_acceleration_cost.h), with λ_a the root-mean-square frequency
/// sqrt(−∫a_a''a_a / ∫a_a²) of the problem's current (the pilot's) a_a, at most `max_rate` rad/s,
/// σ_s the maximum-likelihood intensity of segment s alone (3 axes × (N − 1) increments), the rate
/// a' continuous at the inner breakpoints (the jump rows of the m = 2 prior, σ the geometric mean of
/// the neighbours'), and the stationary law of (a, a') at the first time, a ~ N(0, σ_0²/(4λ³)),
/// a' ~ N(0, σ_0²/(4λ)) per axis: with the energy term, the exact density of the stationary process.
void AddThrustAccelerationPrior(PseudoSpectralProblem<QuadrotorModel>& problem, const QuadrotorParameters& vehicle,
                                double max_rate);

}  // namespace cheval::estim

#pragma once
/// \file
/// Gauss–Legendre quadrature: the one rule of the project (the estimator's exact smoothness
/// integrals, the simulator's integrals of motion).

#include <Eigen/Core>

namespace cheval::cheb {

/// Nodes and weights of a quadrature rule on [-1, 1]: ∫ f ≈ Σ_q weights[q] f(nodes[q]).
struct QuadratureRule {
  Eigen::VectorXd nodes;    ///< increasing order is not guaranteed
  Eigen::VectorXd weights;  ///< all > 0, summing to 2
};

/// The n-point Gauss–Legendre rule on [-1, 1], exact for polynomials of degree <= 2n − 1. Nodes by
/// Newton's method on the Legendre polynomial P_n from cos(π(i + 3/4)/(n + 1/2)); weights
/// 2 / ((1 − x²) P_n'(x)²). n >= 1 (std::invalid_argument otherwise: a bug of the caller).
QuadratureRule GaussLegendre(int n);

}  // namespace cheval::cheb

#pragma once
/// \file
/// ControlRowsCost: rows linear in the controls of a set of nodes, in components of an orthonormal
/// basis — the residual of the control smoothness prior ∫ |u^(m)|² dt / σ² and of its jumps
/// (PseudoSpectralProblem::AddControlSmoothnessPrior; docs/estimator.md, "Residuals").
///
/// Contract. With C the coefficient rows (rows × nodes), U the nodes' controls (nodes × kControl, one
/// parameter block per node), B a basis of c orthonormal columns (kControl × c) and w one weight per
/// component, the residual (row q, component j) is w_j (C U B)_{qj}, stored row-major (q, j). It is
/// linear: the Jacobian of node k's block is, per row q, C(q, k) (B diag(w))ᵀ. With C the
/// Gauss–Legendre rows of u^(m) over a segment (sqrt(w_q L/2) u^(m)(t_q)) and w = 1/σ, the squared
/// norm is Σ_j ∫_s |(Bᵀu)_j^(m)|² dt / σ_j², exactly.

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "cheval/estim/internal/block_cost.h"

namespace cheval::estim::internal {

template <int kControl>
class ControlRowsCost : public BlockCost {
 public:
  using Basis = Eigen::Matrix<double, kControl, Eigen::Dynamic>;

  /// `controls`: the control blocks of the nodes (C's columns, in order); weights start at 1.
  ControlRowsCost(const std::vector<double*>& controls, Eigen::MatrixXd coefficients, Basis basis)
      : coefficients_(std::move(coefficients)), basis_(std::move(basis)),
        weights_(Eigen::VectorXd::Ones(basis_.cols())) {
    for (double* u : controls) AddBlock(u, kControl);
    set_num_residuals(static_cast<int>(coefficients_.rows() * basis_.cols()));
  }
  /// A factor on every row (1/σ).
  void set_weight(double weight) { weights_.setConstant(weight); }
  /// A factor per component (1/σ_j; c entries).
  void set_weights(const Eigen::VectorXd& weights) { weights_ = weights; }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int rows = static_cast<int>(coefficients_.rows()), c = static_cast<int>(basis_.cols());
    const Basis WB = basis_ * weights_.asDiagonal();  // u -> weighted components
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> r(residuals, rows, c);
    r.setZero();
    for (int k = 0; k < static_cast<int>(blocks().size()); ++k) {
      r += coefficients_.col(k) * (Eigen::Map<const Eigen::Matrix<double, 1, kControl>>(parameters[k]) * WB);
      if (jacobians && jacobians[k]) {
        // Residual (q, j) depends on u_k[i] with coefficient C(q, k) (B W)(i, j).
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kControl, Eigen::RowMajor>> J(jacobians[k], rows * c, kControl);
        for (int q = 0; q < rows; ++q) J.middleRows(q * c, c) = coefficients_(q, k) * WB.transpose();
      }
    }
    return true;
  }

 private:
  Eigen::MatrixXd coefficients_;
  Basis basis_;
  Eigen::VectorXd weights_;
};

}  // namespace cheval::estim::internal

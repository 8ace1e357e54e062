#pragma once
/// \file
/// ControlRateCost: the equal-weight control-rate prior at one node
/// (PseudoSpectralProblem::AddControlRatePrior; docs/estimator.md, "Residuals").
///
/// Contract. For node j of a segment of length L and degree N, the residual is
/// sqrt(Δt) (D U)_j / σ with Δt = L / (N + 1) and D the differentiation matrix in t: kControl rows,
/// linear in the controls of the segment's N + 1 nodes (parameter blocks, point order), with
/// Jacobian sqrt(Δt) D_jk / σ · I per node k. Summed over the nodes it weights the clustered
/// Chebyshev nodes equally: a rate penalty, not a quadrature of ∫ |u'|² dt (for that, the control
/// smoothness prior, control_rows_cost.h).

#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/segment.h"

namespace cheval::estim::internal {

template <int kControl>
class ControlRateCost : public BlockCost {
 public:
  /// `length`: the segment's duration (s); `D`: its differentiation matrix on the unit interval.
  ControlRateCost(const Segment& segment, double length, const Eigen::MatrixXd& D, int j, double sigma) {
    const int N = segment.degree();
    const double factor = std::sqrt(length / (N + 1)) * segment.derivative_scale / sigma;
    for (int k = 0; k <= N; ++k) {
      AddBlock(segment.control[k], kControl);
      coefficients_.push_back(factor * D(j, k));
    }
    set_num_residuals(kControl);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    for (int i = 0; i < kControl; ++i) residuals[i] = 0;
    for (size_t k = 0; k < coefficients_.size(); ++k) {
      for (int i = 0; i < kControl; ++i) residuals[i] += coefficients_[k] * parameters[k][i];
      if (jacobians && jacobians[k]) {
        Eigen::Map<Eigen::Matrix<double, kControl, kControl, Eigen::RowMajor>> J(jacobians[k]);
        J = coefficients_[k] * Eigen::Matrix<double, kControl, kControl>::Identity();
      }
    }
    return true;
  }

 private:
  std::vector<double> coefficients_;
};

}  // namespace cheval::estim::internal

#pragma once
/// \file
/// The compression of a cost's rows that measurement_cost.h and delayed_position_cost.h share: rows r
/// with Jacobian J, in groups of `group_rows` that share one robust loss ρ, become
/// [Q₁ᵀ r; sqrt(Σρ − |Q₁ᵀ r|²)] with Jacobian [T; 0] (J = Q [T; 0] after the IRLS weights √ρ' of the
/// loss) — the same cost, gradient and Gauss–Newton matrix in min(rows, columns) + 1 rows.

#include <algorithm>
#include <cmath>

#include <ceres/loss_function.h>
#include <Eigen/Core>
#include <Eigen/QR>

namespace cheval::estim::internal {

/// Σ ρ(|r_g|²) over the groups of `rows` residuals (Σ |r_g|² without a loss).
inline double GroupedCost(const double* r, int rows, int group_rows, const ceres::LossFunction* loss) {
  double cost = 0.0;
  for (int first = 0; first < rows; first += group_rows) {
    double sq = 0.0;
    for (int e = 0; e < group_rows; ++e) sq += r[first + e] * r[first + e];
    double rho[3] = {sq, 1.0, 0.0};
    if (loss != nullptr) loss->Evaluate(sq, rho);
    cost += rho[0];
  }
  return cost;
}

/// The compressed rows of (r, J) (both modified: weighted by √ρ' per group), see the file comment.
inline void CompressRows(int group_rows, const ceres::LossFunction* loss, Eigen::VectorXd* r, Eigen::MatrixXd* J,
                         Eigen::VectorXd* out_r, Eigen::MatrixXd* out_J) {
  double cost = 0.0;  // Σ ρ(s_i) (or s_i without a loss) over the groups
  for (Eigen::Index first = 0; first < r->size(); first += group_rows) {
    auto rg = r->segment(first, group_rows);
    const double s = rg.squaredNorm();
    if (loss == nullptr) {
      cost += s;
      continue;
    }
    double rho[3];
    loss->Evaluate(s, rho);
    cost += rho[0];
    const double root = std::sqrt(std::max(rho[1], 0.0));
    rg *= root;
    J->middleRows(first, group_rows) *= root;
  }
  // J = Q [T; 0]: cost and gradient kept by [Q1ᵀ r; sqrt(cost − |Q1ᵀ r|²)] with Jacobian [T; 0].
  const Eigen::Index rank = std::min(J->rows(), J->cols());
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(*J);
  const Eigen::VectorXd qtr = qr.householderQ().adjoint() * (*r);
  out_r->resize(rank + 1);
  out_r->head(rank) = qtr.head(rank);
  (*out_r)[rank] = std::sqrt(std::max(0.0, cost - out_r->head(rank).squaredNorm()));
  *out_J = Eigen::MatrixXd::Zero(rank + 1, J->cols());
  out_J->topRows(rank) = qr.matrixQR().topRows(rank).template triangularView<Eigen::Upper>();
}

}  // namespace cheval::estim::internal

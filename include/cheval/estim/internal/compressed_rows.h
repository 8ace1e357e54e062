#pragma once
/// \file
/// What the batched costs share (measurement_cost.h, derivative_measurement_cost.h,
/// delayed_position_cost.h): the check of a batch's arguments, and the compression of its rows: rows r
/// with Jacobian J, in groups of `group_rows` that share one robust loss ρ, become
/// [Q₁ᵀ r; sqrt(Σρ − |Q₁ᵀ r|²)] with Jacobian [T; 0] (J = Q [T; 0] after the IRLS weights √ρ' of the
/// loss) — the same cost, gradient and Gauss–Newton matrix in min(rows, columns) + 1 rows.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <ceres/loss_function.h>
#include <Eigen/Core>
#include <Eigen/QR>

#include "cheval/common/error.h"

namespace cheval::estim::internal {

/// The arguments of a batch of measurements (one residual block for several times of one segment,
/// `rows` each in groups of `group_rows` sharing a loss, reading the vector blocks `used` of `blocks`):
/// throws UsageError, naming `what`, for rows that are not a positive multiple of group_rows, a block
/// that does not exist, no samples or a sample (`.row.segment`) of another segment.
template <class Samples>
void CheckBatch(const std::string& what, int rows, int group_rows, const std::vector<int>& used, int blocks,
                const Samples& samples) {
  if (rows < 1 || group_rows < 1 || rows % group_rows != 0) {
    throw UsageError(what + " rows must be a positive multiple of the group size");
  }
  for (int b : used) {
    if (b < 0 || b >= blocks) throw UsageError(what + " uses a vector block that does not exist");
  }
  if (samples.empty()) throw UsageError("a " + what + " batch needs at least one sample");
  for (const auto& sample : samples) {
    if (sample.row.segment != samples.front().row.segment) {
      throw UsageError("the " + what + "s of a batch must lie in one segment");
    }
  }
}

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

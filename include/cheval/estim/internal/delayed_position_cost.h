#pragma once
/// \file
/// DelayedPositionCost: positions stamped by a clock that runs δ behind the problem's (the problem
/// keeps the time of its other measurements, e.g. an IMU whose samples arrive δ late), with δ a
/// parameter block of its own (docs/estimator_real_data.md, "Two clocks").
///
/// Contract. For the samples (t_i, m_i) of one segment, the position at problem time t_i + δ,
///   p(t_i + δ) ≈ p(t_i) + δ v(t_i) + ½ δ² v'(t_i),
/// p(t) = Σ_k w_k(t) P_k, v(t) = Σ_k w_k(t) V_k, v'(t) = Σ_k w'_k(t) V_k through the rows of t_i, is
/// compared with m_i: r_i = (p(t_i + δ) − m_i) / σ, 3 rows per sample with one robust loss each
/// (applied inside: the rows are always compressed, internal/compressed_rows.h). The expansion's
/// error is δ³ |p'''| / 6: 0.2 mm at δ = 30 ms and a jerk of 50 m/s³. Parameter blocks: per node of
/// the segment (point order), the position block then the velocity block (3 each, the model's vector
/// blocks `position_block` and `velocity_block`), then δ (1, seconds). Jacobians analytic.

#include <cmath>
#include <utility>
#include <vector>

#include <ceres/loss_function.h>
#include <Eigen/Core>

#include "cheval/common/error.h"
#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/compressed_rows.h"
#include "cheval/estim/internal/segment.h"

namespace cheval::estim::internal {

class DelayedPositionCost : public BlockCost {
 public:
  /// One position: where its stamp falls in the segment (rows w and w'), and the measured position.
  struct Sample {
    TimeRow row;
    Eigen::Vector3d measured;
  };

  /// `sigma` > 0 (m); `loss` may be null, not owned; `delay` is δ's block (1 number). The vector
  /// blocks must have 3 entries (kBlockSize 3). Throws UsageError for no samples, a sample of another
  /// segment or a σ that is not positive.
  DelayedPositionCost(const Segment& segment, std::vector<Sample> samples, int position_block, int velocity_block,
                      double sigma, const ceres::LossFunction* loss, double* delay)
      : samples_(std::move(samples)), inv_sigma_(1.0 / sigma), loss_(loss), degree_(segment.degree()) {
    if (samples_.empty()) throw UsageError("a delayed position cost needs at least one sample");
    if (!(sigma > 0)) throw UsageError("a delayed position cost needs a sigma > 0");
    for (const Sample& sample : samples_) {
      if (sample.row.segment != segment.index) throw UsageError("the samples of a delayed position cost must lie in its segment");
    }
    for (int k = 0; k <= degree_; ++k) {
      AddBlock(segment.vector[k] + 3 * position_block, 3);
      AddBlock(segment.vector[k] + 3 * velocity_block, 3);
    }
    AddBlock(delay, 1);
    set_num_residuals(std::min(represented_rows(), Columns()) + 1);
  }

  int represented_rows() const override { return 3 * static_cast<int>(samples_.size()); }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int N = degree_, rows = represented_rows();
    const double delay = parameters[2 * (N + 1)][0];
    Eigen::VectorXd r(rows);
    Eigen::MatrixXd J;
    if (jacobians != nullptr) J = Eigen::MatrixXd::Zero(rows, Columns());
    for (size_t i = 0; i < samples_.size(); ++i) {
      const TimeRow& row = samples_[i].row;
      Eigen::Vector3d p = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero(), a = Eigen::Vector3d::Zero();
      for (int k = 0; k <= N; ++k) {
        const Eigen::Map<const Eigen::Vector3d> P(parameters[2 * k]), V(parameters[2 * k + 1]);
        p += row.w[k] * P;
        v += row.w[k] * V;
        a += row.dw[k] * V;
      }
      const Eigen::Index at = 3 * static_cast<Eigen::Index>(i);
      r.segment<3>(at) = inv_sigma_ * (p + delay * v + 0.5 * delay * delay * a - samples_[i].measured);
      if (jacobians == nullptr) continue;
      for (int k = 0; k <= N; ++k) {
        J.block<3, 3>(at, 6 * k).diagonal().setConstant(inv_sigma_ * row.w[k]);
        J.block<3, 3>(at, 6 * k + 3).diagonal().setConstant(inv_sigma_ * (delay * row.w[k] + 0.5 * delay * delay * row.dw[k]));
      }
      J.block<3, 1>(at, 6 * (N + 1)) = inv_sigma_ * (v + delay * a);
    }
    if (jacobians == nullptr) {  // a step's cost: a residual vector of the same squared norm
      Eigen::Map<Eigen::VectorXd>(residuals, num_residuals()).setZero();
      residuals[0] = std::sqrt(GroupedCost(r.data(), rows, 3, loss_));
      return true;
    }
    Eigen::VectorXd out_r;
    Eigen::MatrixXd out_J;
    CompressRows(3, loss_, &r, &J, &out_r, &out_J);
    Eigen::Map<Eigen::VectorXd>(residuals, out_r.size()) = out_r;
    const Eigen::Index m = out_r.size();
    for (int b = 0; b < 2 * (N + 1); ++b) {
      if (jacobians[b] == nullptr) continue;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(jacobians[b], m, 3) = out_J.middleCols(3 * b, 3);
    }
    if (jacobians[2 * (N + 1)] != nullptr) {
      Eigen::Map<Eigen::VectorXd>(jacobians[2 * (N + 1)], m) = out_J.col(6 * (N + 1));
    }
    return true;
  }

 private:
  int Columns() const { return 6 * (degree_ + 1) + 1; }

  std::vector<Sample> samples_;
  double inv_sigma_;
  const ceres::LossFunction* loss_;
  int degree_;
};

}  // namespace cheval::estim::internal

#pragma once
/// \file
/// DerivativeMeasurementCost: a measurement h(x'(t)) of the derivative of the state's vector part at
/// any time t (e.g. an accelerometer on v'), or a batch of them in one segment (docs/estimator.md,
/// "Residuals").
///
/// Contract. x'(t) = Σ_k w'_k(t) X_k through the derivative row of t in its segment (in 1/s). The
/// functor F has `template <class T> bool operator()(const T* x_dot, T* h) const` and returns `rows`
/// whitened residuals, in groups of `group_rows` rows that share one robust loss ρ. Parameter blocks:
/// per node of the segment (point order), the used vector blocks (block order); the others are read
/// from the problem's storage and held. h is differentiated by ceres::Jet; the Jacobian of block b of
/// node k is w'_k ∂h/∂x'_b. A batch — several times of one segment, each with its own functor, e.g.
/// every accelerometer sample in the segment — and any cost whose rows outnumber its columns + 1 are
/// compressed as measurement_cost.h's (internal/compressed_rows.h: the same cost, gradient and
/// Gauss–Newton matrix, the loss applied inside; evaluated without Jacobians only the squared norm
/// of the residuals is meaningful). Without Jacobians h is evaluated in doubles. The rotation is not
/// measured (no body-rate measurement of R).

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <ceres/jet.h>
#include <ceres/loss_function.h>
#include <Eigen/Core>

#include "cheval/common/error.h"
#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/compressed_rows.h"
#include "cheval/estim/internal/segment.h"

namespace cheval::estim::internal {

template <class Model, class F>
class DerivativeMeasurementCost : public BlockCost {
  using Dim = Dims<Model>;
  static constexpr int kVector = Dim::kVector, kBlock = Dim::kBlock, kBlocks = Dim::kBlocks;
  using Vector = Eigen::Matrix<double, kVector, 1>;

 public:
  /// One measurement of a batch: where its time falls in the segment, and its functor.
  struct Sample {
    TimeRow row;
    F functor;
  };

  /// Measurements in `segment`, `rows` each (the loss applies per group of `group_rows`); `used`: the
  /// vector blocks h depends on. `loss` may be null; it is not owned. Throws UsageError for rows that
  /// are not a positive multiple of group_rows, a block that does not exist, no samples or a sample
  /// of another segment.
  DerivativeMeasurementCost(const Segment& segment, std::vector<Sample> samples, int rows, int group_rows,
                            std::vector<int> used, const ceres::LossFunction* loss)
      : storage_(segment.vector), samples_(std::move(samples)), rows_(rows), group_rows_(group_rows),
        used_(std::move(used)), loss_(loss) {
    CheckBatch("derivative measurement", rows_, group_rows_, used_, kBlocks, samples_);
    columns_ = (segment.degree() + 1) * static_cast<int>(used_.size()) * kBlock;
    compress_ = samples_.size() > 1 || represented_rows() > columns_ + 1;
    set_num_residuals(compress_ ? std::min(represented_rows(), columns_) + 1 : rows_);
    for (int k = 0; k <= segment.degree(); ++k) {
      for (int b : used_) AddBlock(segment.vector[k] + b * kBlock, kBlock);
    }
  }
  /// Every measurement's rows, compressed or not.
  int represented_rows() const override { return rows_ * static_cast<int>(samples_.size()); }
  /// The loss Ceres applies: only when the rows are not compressed (then the loss is per block).
  ceres::LossFunction* ceres_loss() const { return compress_ ? nullptr : const_cast<ceres::LossFunction*>(loss_); }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int N = static_cast<int>(storage_.size()) - 1;
    const int used = static_cast<int>(used_.size());
    std::vector<Vector> nodes(N + 1);
    for (int k = 0; k <= N; ++k) nodes[k] = NodeVector<Model>(storage_, used_, parameters, k, used);
    const auto derivative = [&](const TimeRow& row) {
      Vector x_dot = Vector::Zero();
      for (int k = 0; k <= N; ++k) x_dot += row.dw[k] * nodes[k];
      return x_dot;
    };
    if (jacobians == nullptr) {  // a step's cost: h in doubles; compressed, (sqrt(Σ ρ), 0, ..., 0)
      if (!compress_) return samples_.front().functor(derivative(samples_.front().row).data(), residuals);
      std::vector<double> h(rows_);
      double cost = 0.0;
      for (const Sample& sample : samples_) {
        if (!sample.functor(derivative(sample.row).data(), h.data())) return false;
        cost += GroupedCost(h.data(), rows_, group_rows_, loss_);
      }
      std::fill_n(residuals, num_residuals(), 0.0);
      residuals[0] = std::sqrt(cost);
      return true;
    }
    using Jet = ceres::Jet<double, kVector>;
    Eigen::VectorXd r(represented_rows());
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(represented_rows(), columns_);
    std::vector<Jet> h(rows_);
    for (size_t i = 0; i < samples_.size(); ++i) {
      const Sample& sample = samples_[i];
      const Vector x_dot = derivative(sample.row);
      Jet xj[kVector];
      for (int e = 0; e < kVector; ++e) xj[e] = Jet(x_dot[e], e);
      if (!sample.functor(xj, h.data())) return false;
      const Eigen::Index first = static_cast<Eigen::Index>(i) * rows_;
      for (int q = 0; q < rows_; ++q) {
        r[first + q] = h[q].a;
        for (int k = 0; k <= N; ++k) {
          for (int ub = 0; ub < used; ++ub) {
            for (int e = 0; e < kBlock; ++e) {
              J(first + q, (k * used + ub) * kBlock + e) = sample.row.dw[k] * h[q].v[used_[ub] * kBlock + e];
            }
          }
        }
      }
    }
    Eigen::VectorXd out_r = r;
    Eigen::MatrixXd out_J = J;
    if (compress_) CompressRows(group_rows_, loss_, &r, &J, &out_r, &out_J);
    Eigen::Map<Eigen::VectorXd>(residuals, out_r.size()) = out_r;
    const Eigen::Index m = out_r.size();
    for (int b = 0; b < (N + 1) * used; ++b) {
      if (jacobians[b] == nullptr) continue;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kBlock, Eigen::RowMajor>>(jacobians[b], m, kBlock) =
          out_J.middleCols(b * kBlock, kBlock);
    }
    return true;
  }

 private:
  std::vector<double*> storage_;  // every node's vector part (point order): the blocks h does not use
  std::vector<Sample> samples_;
  int rows_, group_rows_;
  std::vector<int> used_;
  const ceres::LossFunction* loss_;
  int columns_ = 0;
  bool compress_ = false;
};

}  // namespace cheval::estim::internal

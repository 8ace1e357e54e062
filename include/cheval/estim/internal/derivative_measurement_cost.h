#pragma once
/// \file
/// DerivativeMeasurementCost: a measurement h(x'(t)) of the derivative of the state's vector part at
/// any time t (e.g. an accelerometer on v'; docs/estimator.md, "Residuals").
///
/// Contract. x'(t) = Σ_k w'_k(t) X_k through the derivative row of t in its segment (in 1/s). The
/// functor F has `template <class T> bool operator()(const T* x_dot, T* h) const` and returns `rows`
/// whitened residuals. Parameter blocks: every vector block of every node of the segment (point
/// order, then block order). h is differentiated by ceres::Jet; the Jacobian of block b of node k is
/// w'_k ∂h/∂x'_b. The rotation is not measured (no body-rate measurement of R).

#include <vector>

#include <ceres/jet.h>
#include <Eigen/Core>

#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/segment.h"

namespace cheval::estim::internal {

template <class Model, class F>
class DerivativeMeasurementCost : public BlockCost {
  using Dim = Dims<Model>;
  static constexpr int kVector = Dim::kVector, kBlock = Dim::kBlock, kBlocks = Dim::kBlocks;

 public:
  DerivativeMeasurementCost(const Segment& segment, TimeRow row, F functor, int rows)
      : degree_(segment.degree()), row_(std::move(row)), f_(std::move(functor)), rows_(rows) {
    set_num_residuals(rows);
    for (int k = 0; k <= degree_; ++k) {
      for (int b = 0; b < kBlocks; ++b) AddBlock(segment.vector[k] + b * kBlock, kBlock);
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    using Jet = ceres::Jet<double, kVector>;
    Eigen::Matrix<double, kVector, 1> xdot = Eigen::Matrix<double, kVector, 1>::Zero();
    for (int k = 0; k <= degree_; ++k) {
      for (int b = 0; b < kBlocks; ++b) {
        xdot.segment(b * kBlock, kBlock) +=
            row_.dw[k] * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(parameters[k * kBlocks + b]);
      }
    }
    Jet xj[kVector];
    for (int i = 0; i < kVector; ++i) xj[i] = Jet(xdot[i], i);
    std::vector<Jet> h(rows_);
    if (!f_(xj, h.data())) return false;
    for (int i = 0; i < rows_; ++i) residuals[i] = h[i].a;
    if (jacobians == nullptr) return true;
    for (int k = 0; k <= degree_; ++k) {
      for (int b = 0; b < kBlocks; ++b) {
        double* jac = jacobians[k * kBlocks + b];
        if (jac == nullptr) continue;
        for (int i = 0; i < rows_; ++i) {
          for (int e = 0; e < kBlock; ++e) jac[i * kBlock + e] = row_.dw[k] * h[i].v[b * kBlock + e];
        }
      }
    }
    return true;
  }

 private:
  int degree_;
  TimeRow row_;
  F f_;
  int rows_;
};

}  // namespace cheval::estim::internal

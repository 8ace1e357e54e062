#pragma once
/// \file
/// MeasurementCost: a measurement h(x(t), R(t)) of the state at any time t (docs/estimator.md,
/// "Residuals").
///
/// Contract. x(t) = Σ_k w_k(t) X_k through the barycentric row of t in its segment, and
/// R(t) = R̄ Exp(Σ_k w_k(t) φ_k), φ_k = Log(R̄ᵀ R_k). The functor F has
/// `template <class T> bool operator()(const T* x, const Eigen::Matrix<T,3,3>& R, T* h) const` and
/// returns `rows` residuals, already whitened, in groups of `group_rows` rows that share one robust
/// loss ρ (a camera frame: 2 rows per landmark). When rows > used tangent + 1 the rows are
/// compressed: with J = Q [T; 0] the QR of their Jacobian (after the IRLS weights √ρ' of the loss),
/// the cost returns [Q₁ᵀ r; sqrt(Σρ − |Q₁ᵀ r|²)] with Jacobian [T; 0] — the same cost, gradient and
/// Gauss–Newton matrix as the original rows, with the loss applied inside (ceres_loss() is then
/// null). Evaluated without Jacobians, a compressed cost returns (sqrt(Σρ), 0, …, 0): only its
/// squared norm is meaningful. Parameter blocks: per node of the segment (point order), the used
/// vector blocks, then the quaternion (models with a rotation, unless the measurement is declared
/// not to use it: then h's R is the identity, and the node's rotation is none of its blocks). h is differentiated by ceres::Jet in
/// the local tangent at t and carried to the nodes through the row (rotation: J_r(φ(t)) J_r⁻¹(φ_k));
/// without Jacobians (Ceres pricing a step) h is evaluated in doubles.

#include <algorithm>
#include <cmath>
#include <vector>

#include <ceres/jet.h>
#include <ceres/loss_function.h>
#include <Eigen/Core>
#include <Eigen/QR>

#include "cheval/common/error.h"
#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/segment.h"
#include "cheval/estim/manifold.h"
#include "cheval/lie/so3.h"

namespace cheval::estim::internal {

template <class Model, class F>
class MeasurementCost : public BlockCost {
  using Dim = Dims<Model>;
  static constexpr int kVector = Dim::kVector, kBlock = Dim::kBlock, kBlocks = Dim::kBlocks,
                       kTangent = Dim::kTangent;
  static constexpr bool kRotation = Dim::kRotation;

 public:
  /// `used`: the vector blocks h depends on (the others are read from the segment's storage and
  /// held); `uses_rotation`: whether h depends on R (models with a rotation). `loss` may be null; it
  /// is not owned. Throws UsageError for rows that are not a positive multiple of group_rows or a
  /// block that does not exist.
  MeasurementCost(const Segment& segment, TimeRow row, F functor, int rows, int group_rows, std::vector<int> used,
                  const ceres::LossFunction* loss, bool uses_rotation = true)
      : storage_(segment.vector), reference_(segment.reference), row_(std::move(row)), f_(std::move(functor)),
        rows_(rows), group_rows_(group_rows), used_(std::move(used)), loss_(loss),
        rotation_(kRotation && uses_rotation) {
    if (rows_ < 1 || group_rows_ < 1 || rows_ % group_rows_ != 0) {
      throw UsageError("measurement rows must be a positive multiple of the group size");
    }
    for (int b : used_) {
      if (b < 0 || b >= kBlocks) throw UsageError("measurement uses a vector block that does not exist");
    }
    used_dim_ = static_cast<int>(used_.size()) * kBlock + (rotation_ ? 3 : 0);
    compress_ = rows_ > used_dim_ + 1;
    set_num_residuals(compress_ ? used_dim_ + 1 : rows_);
    for (int k = 0; k <= segment.degree(); ++k) {
      for (int b : used_) AddBlock(segment.vector[k] + b * kBlock, kBlock);
      if (rotation_) AddBlock(segment.quaternion[k], 4);
    }
  }
  int segment() const { return row_.segment; }
  /// The loss Ceres applies: only when the rows are not compressed (then the loss is per block).
  ceres::LossFunction* ceres_loss() const { return compress_ ? nullptr : const_cast<ceres::LossFunction*>(loss_); }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int N = static_cast<int>(storage_.size()) - 1;
    const int per_node = static_cast<int>(used_.size()) + (rotation_ ? 1 : 0);
    // Interpolated state: used blocks from the parameters, the others from the problem's storage.
    Eigen::Matrix<double, kVector, 1> x = Eigen::Matrix<double, kVector, 1>::Zero();
    Eigen::Vector3d phi = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector3d> phis;
    if (rotation_) phis.resize(N + 1);
    for (int k = 0; k <= N; ++k) {
      for (int b = 0; b < kBlocks; ++b) {
        const auto it = std::find(used_.begin(), used_.end(), b);
        const double* src = it == used_.end() ? storage_[k] + b * kBlock
                                              : parameters[k * per_node + static_cast<int>(it - used_.begin())];
        x.segment(b * kBlock, kBlock) += row_.w[k] * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(src);
      }
      if (rotation_) {
        phis[k] = ChartVector(reference_, parameters[k * per_node + per_node - 1]);
        phi += row_.w[k] * phis[k];
      }
    }
    if (jacobians == nullptr) {
      // Residual only (a step's cost): h in doubles. Compressed, a residual vector with the same
      // squared norm, (sqrt(Σ ρ), 0, ..., 0).
      Eigen::Matrix3d R_t = Eigen::Matrix3d::Identity();
      if (rotation_) R_t = reference_ * lie::SO3d::Exp(phi).Matrix();
      if (!compress_) return f_(x.data(), R_t, residuals);
      std::vector<double> h(rows_);
      if (!f_(x.data(), R_t, h.data())) return false;
      double cost = 0.0;
      for (int gi = 0; gi < rows_ / group_rows_; ++gi) {
        double sq = 0.0;
        for (int e = 0; e < group_rows_; ++e) sq += h[gi * group_rows_ + e] * h[gi * group_rows_ + e];
        double rho[3] = {sq, 1.0, 0.0};
        if (loss_ != nullptr) loss_->Evaluate(sq, rho);
        cost += rho[0];
      }
      std::fill_n(residuals, used_dim_ + 1, 0.0);
      residuals[0] = std::sqrt(cost);
      return true;
    }
    // h and its Jacobian in the local tangent (x, δ) at t.
    using Jet = ceres::Jet<double, kTangent>;
    Jet xj[kVector];
    for (int i = 0; i < kVector; ++i) xj[i] = Jet(x[i], i);
    Eigen::Matrix<Jet, 3, 3> R = Eigen::Matrix<Jet, 3, 3>::Identity();
    Eigen::Matrix3d jr_t = Eigen::Matrix3d::Identity();
    if constexpr (kRotation) {  // (a model without a rotation has no δ in its tangent)
      if (rotation_) {
        Eigen::Matrix<Jet, 3, 1> delta;
        for (int i = 0; i < 3; ++i) delta[i] = Jet(0.0, kVector + i);
        const Eigen::Matrix3d R_t = reference_ * lie::SO3d::Exp(phi).Matrix();
        R = R_t.cast<Jet>() * lie::SO3<Jet>::Exp(delta).Matrix();
        jr_t = lie::SO3d::RightJacobian(phi);
      }
    }
    std::vector<Jet> h(rows_);
    if (!f_(xj, R, h.data())) return false;
    // Columns of the used tangent: used blocks, then the rotation.
    Eigen::VectorXd r(rows_);
    Eigen::MatrixXd J(rows_, used_dim_);
    for (int i = 0; i < rows_; ++i) {
      r[i] = h[i].a;
      int c = 0;
      for (int b : used_) {
        for (int e = 0; e < kBlock; ++e) J(i, c++) = h[i].v[b * kBlock + e];
      }
      if (rotation_) {
        for (int e = 0; e < 3; ++e) J(i, c++) = h[i].v[kVector + e];
      }
    }
    Eigen::VectorXd out_r;
    Eigen::MatrixXd out_J;
    if (!compress_) {
      out_r = r;
      out_J = J;
    } else {
      double cost = 0.0;  // Σ ρ(s_i) (or s_i without a loss) over the groups
      for (int gi = 0; gi < rows_ / group_rows_; ++gi) {
        auto rg = r.segment(gi * group_rows_, group_rows_);
        const double s = rg.squaredNorm();
        if (loss_ == nullptr) {
          cost += s;
          continue;
        }
        double rho[3];
        loss_->Evaluate(s, rho);
        cost += rho[0];
        const double root = std::sqrt(std::max(rho[1], 0.0));
        rg *= root;
        J.middleRows(gi * group_rows_, group_rows_) *= root;
      }
      // J = Q [T; 0]: cost and gradient kept by [Q1ᵀ r; sqrt(cost − |Q1ᵀ r|²)] with Jacobian [T; 0].
      Eigen::HouseholderQR<Eigen::MatrixXd> qr(J);
      const Eigen::VectorXd qtr = qr.householderQ().adjoint() * r;
      out_r.resize(used_dim_ + 1);
      out_r.head(used_dim_) = qtr.head(used_dim_);
      out_r[used_dim_] = std::sqrt(std::max(0.0, cost - out_r.head(used_dim_).squaredNorm()));
      out_J = Eigen::MatrixXd::Zero(used_dim_ + 1, used_dim_);
      out_J.topRows(used_dim_) = qr.matrixQR().topRows(used_dim_).template triangularView<Eigen::Upper>();
    }
    Eigen::Map<Eigen::VectorXd>(residuals, out_r.size()) = out_r;
    if (jacobians == nullptr) return true;
    const int m = static_cast<int>(out_r.size());
    for (int k = 0; k <= N; ++k) {
      int c = 0;
      for (size_t ub = 0; ub < used_.size(); ++ub, c += kBlock) {
        double* jac = jacobians[k * per_node + static_cast<int>(ub)];
        if (jac == nullptr) continue;
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, kBlock, Eigen::RowMajor>>(jac, m, kBlock) =
            row_.w[k] * out_J.middleCols(c, kBlock);
      }
      if (rotation_) {
        double* jac = jacobians[k * per_node + per_node - 1];
        if (jac == nullptr) continue;
        const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Jd =
            row_.w[k] * out_J.middleCols(c, 3) * jr_t * lie::SO3d::InverseRightJacobian(phis[k]);
        LiftRotationJacobian(parameters[k * per_node + per_node - 1], Jd.data(), m, jac);
      }
    }
    return true;
  }

 private:
  std::vector<double*> storage_;  // every node's vector part (point order): the blocks h does not use
  Eigen::Matrix3d reference_;
  TimeRow row_;
  F f_;
  int rows_, group_rows_;
  std::vector<int> used_;
  const ceres::LossFunction* loss_;
  bool rotation_;
  int used_dim_ = 0;
  bool compress_ = false;
};

}  // namespace cheval::estim::internal

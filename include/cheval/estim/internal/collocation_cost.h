#pragma once
/// \file
/// CollocationCost: the defect of the dynamics at one node (Agrawal & Dellaert, ICRA 2021, eq. 13;
/// docs/estimator.md, "Residuals").
///
/// Contract. For node j of a segment (point order, segment.h) and one part of the state — a vector
/// block b, or the rotation — the residual is
///   vector block b:  ((D X_b)_j − f_b(X_j, R_j, U_j)) / σ_b,
///   rotation:        (J_r(φ_j) (D φ)_j − ω(X_j, R_j, U_j)) / σ_R,   φ_k = Log(R̄ᵀ R_k),
/// with D the segment's differentiation matrix in t, f and ω the model's Dynamics and σ one entry per
/// row. ω = J_r(φ) φ' is the exact body rate of R(t) = R̄ Exp(φ(t)) (ω = φ' holds only at φ = 0).
/// Parameter blocks: the part at the N + 1 nodes of the segment (point order), then node j's other
/// vector blocks, its quaternion (vector parts only) and its control. Jacobians are analytic through
/// D; f and ω are differentiated by ceres::Jet; rotation Jacobians are lifted to the quaternion's
/// four coefficients (LiftRotationJacobian).

#include <algorithm>

#include <ceres/jet.h>
#include <Eigen/Core>

#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/segment.h"
#include "cheval/estim/manifold.h"
#include "cheval/lie/so3.h"

namespace cheval::estim::internal {

template <class Model>
class CollocationCost : public BlockCost {
  using Dim = Dims<Model>;
  static constexpr int kVector = Dim::kVector, kBlock = Dim::kBlock, kBlocks = Dim::kBlocks,
                       kControl = Dim::kControl, kTangent = Dim::kTangent;
  static constexpr bool kRotation = Dim::kRotation;

 public:
  /// `D`: the segment's differentiation matrix on the unit interval (point order); `part` in
  /// [0, kBlocks] (kBlocks: the rotation); `sigma`: kTangent entries > 0 (vector part, then rotation).
  CollocationCost(const Model& model, const Segment& segment, const Eigen::MatrixXd& D, int j, int part,
                  const Eigen::Matrix<double, kTangent, 1>& sigma)
      : model_(model), degree_(segment.degree()), scale_(segment.derivative_scale), reference_(segment.reference),
        d_(D.row(j)), j_(j), part_(part), rotation_part_(part == kBlocks) {
    const int N = degree_;
    rows_ = rotation_part_ ? 3 : kBlock;
    for (int k = 0; k <= N; ++k) {
      if (rotation_part_) AddBlock(segment.quaternion[k], 4);
      else AddBlock(segment.vector[k] + part * kBlock, kBlock);
    }
    for (int b = 0; b < kBlocks; ++b) {
      if (!rotation_part_ && b == part) continue;
      local_blocks_.push_back(b);
      AddBlock(segment.vector[j] + b * kBlock, kBlock);
    }
    if (kRotation && !rotation_part_) AddBlock(segment.quaternion[j], 4);
    AddBlock(segment.control[j], kControl);
    set_num_residuals(rows_);
    const int offset = rotation_part_ ? kVector : part * kBlock;
    inv_sigma_ = sigma.segment(offset, rows_).cwiseInverse();
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int N = degree_;
    const double scale = scale_;
    // Node j's full state and control, from the parameter blocks of this residual.
    Eigen::Matrix<double, kVector, 1> x;
    const double* q_j = nullptr;
    int next = N + 1;
    if (rotation_part_) {
      for (int b = 0; b < kBlocks; ++b) std::copy_n(parameters[next++], kBlock, x.data() + b * kBlock);
      q_j = parameters[j_];
    } else {
      std::copy_n(parameters[j_], kBlock, x.data() + part_ * kBlock);
      for (int b : local_blocks_) std::copy_n(parameters[next++], kBlock, x.data() + b * kBlock);
      if (kRotation) q_j = parameters[next++];
    }
    const double* u = parameters[next];
    if (jacobians == nullptr && !rotation_part_) {  // residual only: f in doubles
      double xdot_d[kVector], omega_d[3];
      const Eigen::Matrix3d Rj = kRotation ? QuaternionMatrix(q_j) : Eigen::Matrix3d::Identity();
      model_.Dynamics(x.data(), Rj, u, xdot_d, omega_d);
      Eigen::Matrix<double, kBlock, 1> r = -Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(xdot_d + part_ * kBlock);
      for (int k = 0; k <= N; ++k) {
        r += scale * d_[k] * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(parameters[k]);
      }
      Eigen::Map<Eigen::VectorXd>{residuals, rows_} = inv_sigma_.cwiseProduct(r);
      return true;
    }
    // f and its Jacobian with respect to (x, δ, u) by Jets.
    using Jet = ceres::Jet<double, kTangent + kControl>;
    Jet xj[kVector], uj[kControl], xdot[kVector], omega[3];
    for (int i = 0; i < kVector; ++i) xj[i] = Jet(x[i], i);
    for (int i = 0; i < kControl; ++i) uj[i] = Jet(u[i], kTangent + i);
    Eigen::Matrix<Jet, 3, 3> R = Eigen::Matrix<Jet, 3, 3>::Identity();
    if constexpr (kRotation) {
      Eigen::Matrix<Jet, 3, 1> delta;
      for (int i = 0; i < 3; ++i) delta[i] = Jet(0.0, kVector + i);
      R = QuaternionMatrix(q_j).template cast<Jet>() * lie::SO3<Jet>::Exp(delta).Matrix();
    }
    model_.Dynamics(xj, R, uj, xdot, omega);
    const Jet* f = rotation_part_ ? omega : xdot + part_ * kBlock;
    Eigen::Matrix<double, Eigen::Dynamic, kTangent + kControl> df(rows_, kTangent + kControl);
    Eigen::VectorXd r(rows_);
    for (int i = 0; i < rows_; ++i) {
      r[i] = -f[i].a;
      df.row(i) = f[i].v.transpose();
    }
    Charts charts;
    Eigen::Matrix3d jr_j = Eigen::Matrix3d::Identity(), djr = Eigen::Matrix3d::Zero();
    if (rotation_part_) {
      charts = Charts(reference_, parameters, N + 1);
      Eigen::Vector3d phi_dot = Eigen::Vector3d::Zero();
      for (int k = 0; k <= N; ++k) phi_dot += scale * d_[k] * charts.phi[k];
      // J_r(φ_j) φ'_j and its derivative in φ_j (Jets).
      using Jet3 = ceres::Jet<double, 3>;
      Eigen::Matrix<Jet3, 3, 1> phi_j;
      for (int i = 0; i < 3; ++i) phi_j[i] = Jet3(charts.phi[j_][i], i);
      const Eigen::Matrix<Jet3, 3, 1> rate = lie::SO3<Jet3>::RightJacobian(phi_j) * phi_dot.cast<Jet3>();
      for (int i = 0; i < 3; ++i) {
        r[i] += rate[i].a;
        djr.row(i) = rate[i].v.transpose();
      }
      jr_j = lie::SO3d::RightJacobian(charts.phi[j_]);
    } else {
      for (int k = 0; k <= N; ++k) {
        r += scale * d_[k] * Eigen::Map<const Eigen::Matrix<double, kBlock, 1>>(parameters[k]);
      }
    }
    Eigen::Map<Eigen::VectorXd>(residuals, rows_) = inv_sigma_.cwiseProduct(r);
    if (jacobians == nullptr) return true;
    const auto W = inv_sigma_.asDiagonal();
    for (int k = 0; k <= N; ++k) {
      if (jacobians[k] == nullptr) continue;
      if (rotation_part_) {
        Eigen::Matrix3d J = jr_j * (scale * d_[k]) * charts.jr_inv[k];
        if (k == j_) J += djr * charts.jr_inv[k] - df.template block<3, 3>(0, kVector);
        const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Jw = W * J;
        LiftRotationJacobian(parameters[k], Jw.data(), 3, jacobians[k]);
      } else {
        Eigen::Matrix<double, kBlock, kBlock> J = (scale * d_[k]) * Eigen::Matrix<double, kBlock, kBlock>::Identity();
        if (k == j_) J -= df.template block<kBlock, kBlock>(0, part_ * kBlock);
        Eigen::Map<Eigen::Matrix<double, kBlock, kBlock, Eigen::RowMajor>>{jacobians[k]} = W * J;
      }
    }
    next = N + 1;
    auto map = [&](int index, int cols) {
      return Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(jacobians[index], rows_,
                                                                                               cols);
    };
    if (rotation_part_) {
      for (int b = 0; b < kBlocks; ++b, ++next) {
        if (jacobians[next]) map(next, kBlock) = -(W * df.block(0, b * kBlock, rows_, kBlock));
      }
    } else {
      for (int b : local_blocks_) {
        if (jacobians[next]) map(next, kBlock) = -(W * df.block(0, b * kBlock, rows_, kBlock));
        ++next;
      }
      if (kRotation) {
        if (jacobians[next]) {
          const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> Jd = -(W * df.block(0, kVector, rows_, 3));
          LiftRotationJacobian(q_j, Jd.data(), rows_, jacobians[next]);
        }
        ++next;
      }
    }
    if (jacobians[next]) map(next, kControl) = -(W * df.block(0, kTangent, rows_, kControl));
    return true;
  }

 private:
  Model model_;
  int degree_;
  double scale_;
  Eigen::Matrix3d reference_;
  Eigen::RowVectorXd d_;  // row j of D on the unit interval
  int j_, part_;
  bool rotation_part_;
  int rows_ = 0;
  std::vector<int> local_blocks_;
  Eigen::VectorXd inv_sigma_;
};

}  // namespace cheval::estim::internal

#pragma once
/// \file
/// ParametricCollocationCost: the collocation defect of one vector block of the rotor model
/// (rotor_model.h) at one node, with the rotor accelerations the angular dynamics need and, when
/// identifying, the model's parameters θ as a parameter block of their own — the residual that lets
/// `identify rotors` estimate θ jointly with the trajectory and `estimate rotors` use it.
///
/// Contract. For node j of a segment (point order, segment.h) and vector block b (1: v, 2: ω):
///   ((D X_b)_j − f_b(X_j, R_j, U_j, (D U)_j; θ)) / σ_b,
/// CollocationCost's vector-block residual (collocation_cost.h) with f = RotorDynamics and the
/// rotor accelerations U' = D U of the control polynomial (used by ω' only: the rotors' reaction
/// torque). Parameter blocks: block b at the N + 1 nodes (point order), node j's other two vector
/// blocks, its quaternion (x, y, z, w), the control — at the N + 1 nodes for b = 2, at node j for
/// b = 1 — then θ (kRotorThetaSize) when `kIdentify`; otherwise θ is the constant given. Jacobians
/// analytic through D; f by ceres::Jet in (x_j, δ_j, u_j, u'_j[, θ]), the rotation's lifted to the
/// quaternion (LiftRotationJacobian). Without Jacobians (Ceres pricing a step) f is evaluated in
/// doubles, the same residual at a fraction of the cost.

#include <type_traits>

#include <ceres/jet.h>
#include <Eigen/Core>

#include "cheval/estim/internal/block_cost.h"
#include "cheval/estim/internal/segment.h"
#include "cheval/estim/manifold.h"
#include "cheval/estim/rotor_model.h"
#include "cheval/lie/so3.h"

namespace cheval::estim::internal {

template <bool kIdentify>
class ParametricCollocationCost : public BlockCost {
  static constexpr int kTheta = kIdentify ? kRotorThetaSize : 0;
  static constexpr int kJet = 9 + 3 + 4 + 4 + kTheta;  // x, δ, u, u', θ

 public:
  /// `D`: the segment's differentiation matrix on the unit interval; `part` 1 or 2; `sigma` > 0;
  /// `theta`: a parameter block of the problem when kIdentify, else values read now.
  ParametricCollocationCost(const RotorNominal& nominal, const Segment& segment, const Eigen::MatrixXd& D, int j,
                            int part, double sigma, double* theta)
      : nominal_(nominal), degree_(segment.degree()), scale_(segment.derivative_scale), d_(D.row(j)), j_(j),
        part_(part), inv_sigma_(1.0 / sigma), all_controls_(part == 2) {
    for (int k = 0; k <= degree_; ++k) AddBlock(segment.vector[k] + 3 * part, 3);
    for (int b = 0; b < 3; ++b) {
      if (b != part) AddBlock(segment.vector[j] + 3 * b, 3);
    }
    AddBlock(segment.quaternion[j], 4);
    if (all_controls_) {
      for (int k = 0; k <= degree_; ++k) AddBlock(segment.control[k], 4);
    } else {
      AddBlock(segment.control[j], 4);
    }
    if constexpr (kIdentify) {
      AddBlock(theta, kRotorThetaSize);
    } else {
      theta_ = Eigen::Map<const RotorThetaVector>(theta);
    }
    set_num_residuals(3);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    if (jacobians == nullptr) {  // a step's cost: the model in doubles
      double f[3];
      ModelRate(parameters, f);
      WriteResidual(parameters, Eigen::Map<const Eigen::Vector3d>(f), residuals);
      return true;
    }
    const int N = degree_;
    using Jet = ceres::Jet<double, kJet>;
    Jet f_jet[3];
    ModelRate(parameters, f_jet);
    Eigen::Vector3d f;
    for (int i = 0; i < 3; ++i) f[i] = f_jet[i].a;
    WriteResidual(parameters, f, residuals);
    Eigen::Matrix<double, 3, kJet> df;
    for (int i = 0; i < 3; ++i) df.row(i) = f_jet[i].v.transpose();
    df *= -inv_sigma_;
    using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    using RowMajor34 = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;
    for (int k = 0; k <= N; ++k) {
      if (jacobians[k] == nullptr) continue;
      RowMajor3 J = (inv_sigma_ * scale_ * d_[k]) * RowMajor3::Identity();
      if (k == j_) J += df.template block<3, 3>(0, 3 * part_);
      Eigen::Map<RowMajor3>{jacobians[k]} = J;
    }
    int next = N + 1;
    for (int b = 0; b < 3; ++b) {
      if (b == part_) continue;
      if (jacobians[next]) Eigen::Map<RowMajor3>{jacobians[next]} = df.template block<3, 3>(0, 3 * b);
      ++next;
    }
    if (jacobians[next]) {
      const RowMajor3 Jd = df.template block<3, 3>(0, 9);
      LiftRotationJacobian(parameters[next], Jd.data(), 3, jacobians[next]);
    }
    ++next;
    if (all_controls_) {  // u_j directly, and u'_j = scale Σ_k d_k u_k
      for (int k = 0; k <= N; ++k, ++next) {
        if (jacobians[next] == nullptr) continue;
        RowMajor34 J = (scale_ * d_[k]) * df.template block<3, 4>(0, 16);
        if (k == j_) J += df.template block<3, 4>(0, 12);
        Eigen::Map<RowMajor34>{jacobians[next]} = J;
      }
    } else {
      if (jacobians[next]) Eigen::Map<RowMajor34>{jacobians[next]} = df.template block<3, 4>(0, 12);
      ++next;
    }
    if constexpr (kIdentify) {
      if (jacobians[next]) {
        Eigen::Map<Eigen::Matrix<double, 3, kRotorThetaSize, Eigen::RowMajor>>{jacobians[next]} =
            df.template block<3, kRotorThetaSize>(0, 20);
      }
    }
    return true;
  }

 private:
  // ((D X_b)_j − f) / σ, block b's rate at node j from its values at the nodes.
  void WriteResidual(double const* const* parameters, const Eigen::Vector3d& f, double* residuals) const {
    Eigen::Vector3d r = -f;
    for (int k = 0; k <= degree_; ++k) r += scale_ * d_[k] * Eigen::Map<const Eigen::Vector3d>(parameters[k]);
    Eigen::Map<Eigen::Vector3d>{residuals} = inv_sigma_ * r;
  }

  // f_b at node j from the parameter blocks, every input as T: with T = ceres::Jet the inputs carry
  // the derivative slots x 0–8, δ 9–11 (the rotation's tangent at R_j), u 12–15, u' 16–19, θ 20–;
  // with T = double they are the values.
  template <class T>
  void ModelRate(double const* const* parameters, T* f) const {
    const auto input = [](double value, int slot) {
      if constexpr (std::is_same_v<T, double>) {
        return value;
      } else {
        return T(value, slot);
      }
    };
    const int N = degree_;
    T x[9], u[4], u_dot[4], theta[kRotorThetaSize], x_dot[9];
    for (int i = 0; i < 3; ++i) x[3 * part_ + i] = input(parameters[j_][i], 3 * part_ + i);
    int next = N + 1;
    for (int b = 0; b < 3; ++b) {
      if (b == part_) continue;
      for (int i = 0; i < 3; ++i) x[3 * b + i] = input(parameters[next][i], 3 * b + i);
      ++next;
    }
    const double* q = parameters[next++];
    const int controls = next;
    const double* u_j = parameters[controls + (all_controls_ ? j_ : 0)];
    Eigen::Vector4d rate = Eigen::Vector4d::Zero();
    if (all_controls_) {
      for (int k = 0; k <= N; ++k) rate += scale_ * d_[k] * Eigen::Map<const Eigen::Vector4d>(parameters[controls + k]);
    }
    next += all_controls_ ? N + 1 : 1;
    for (int i = 0; i < 4; ++i) {
      u[i] = input(u_j[i], 12 + i);
      u_dot[i] = input(rate[i], 16 + i);
    }
    for (int i = 0; i < kRotorThetaSize; ++i) {
      if constexpr (kIdentify) theta[i] = input(parameters[next][i], 20 + i);
      else theta[i] = T(theta_[i]);
    }
    Eigen::Matrix<T, 3, 3> R;
    if constexpr (std::is_same_v<T, double>) {
      R = QuaternionMatrix(q);
    } else {
      Eigen::Matrix<T, 3, 1> delta;
      for (int i = 0; i < 3; ++i) delta[i] = input(0.0, 9 + i);
      R = QuaternionMatrix(q).cast<T>() * lie::SO3<T>::Exp(delta).Matrix();
    }
    RotorDynamics(nominal_, x, R, u, u_dot, theta, x_dot);
    for (int i = 0; i < 3; ++i) f[i] = x_dot[3 * part_ + i];
  }

  RotorNominal nominal_;
  int degree_;
  double scale_;
  Eigen::RowVectorXd d_;
  int j_, part_;
  double inv_sigma_;
  bool all_controls_;
  RotorThetaVector theta_ = RotorThetaVector::Zero();
};

}  // namespace cheval::estim::internal

#pragma once
/// \file
/// Rotations as Ceres parameter blocks: a unit quaternion (Eigen storage x, y, z, w) with the right
/// perturbation q ⊞ δ = q ⊗ Exp(δ) (δ a rotation vector in the body frame), as cheval::lie::SO3.

#include <ceres/manifold.h>

#include <Eigen/Core>

namespace cheval::estim {

/// ∂(q ⊗ Exp(δ))/∂δ at δ = 0 for a unit quaternion q (x, y, z, w): ½ [w I + [v]× ; −vᵀ] (4 x 3).
Eigen::Matrix<double, 4, 3> QuaternionPlusJacobian(const double* q_xyzw);

/// Converts a Jacobian with respect to the right perturbation δ of a rotation (rows x 3) into the
/// Jacobian with respect to the quaternion's 4 coefficients that Ceres expects: J_q = J_δ · 4 Mᵀ with
/// M = QuaternionPlusJacobian(q). Because MᵀM = ¼ I for a unit quaternion, J_q · M = J_δ exactly, and
/// J_q is the true derivative of any function of the rotation (such functions do not change along q).
void LiftRotationJacobian(const double* q_xyzw, const double* J_delta, int rows, double* J_q);

/// Ceres manifold of unit quaternions (x, y, z, w) with Plus(q, δ) = q ⊗ Exp(δ) and
/// Minus(y, x) = Log(x⁻¹ ⊗ y).
class RightQuaternionManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace cheval::estim

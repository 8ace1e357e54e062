#pragma once
/// \file
/// SE_2(3), the group of extended poses (R, p, v) = [[R p v], [0 1 0], [0 0 1]] (5x5) of a
/// navigation state: attitude, position and linear velocity, templated on the scalar so that
/// ceres::Jet passes through. Composition (R1R2, R1p2 + p1, R1v2 + v1), inverse (Rᵀ, −Rᵀp, −Rᵀv)
/// (the state of the ASE, docs/lie.md).
///
/// | group | storage (order)                   | tangent τ (order)                 | dim |
/// |-------|-----------------------------------|-----------------------------------|-----|
/// | SE23  | (SO3 R, position p, velocity v)   | (ω, ρ_p, ρ_v), rotation first     | 9   |
///
/// (GTSAM's NavState orders its tangent (R, t, v) too, while manif's SE_2(3) stores (p, q, v);
/// cheval puts rotation first in every group, in storage and in the tangent.)
///
/// Exp(ω, ρ_p, ρ_v) = (Exp(ω), V ρ_p, V ρ_v) with V = SO3::LeftJacobian(ω) for both. The
/// conventions for Plus/Minus, Jacobians and Adj are those of lie_group_base.h. A state
/// X = X_w_b holds R_w_b, the position p of b in w (metres) and the velocity v of b in w (m/s,
/// world frame).

#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/lie/detail.h"
#include "cheval/lie/lie_group_base.h"
#include "cheval/lie/so3.h"

namespace cheval::lie {

/// An extended pose (R, p, v); tangent (ω, ρ_p, ρ_v) ∈ R⁹, rotation first.
template <typename T>
class SE23 : public LieGroupBase<SE23<T>, T, 9, 5> {
 public:
  /// The base: the types (Tangent, Jacobian, ...) and the algebra shared by the groups.
  using Base = LieGroupBase<SE23<T>, T, 9, 5>;
  CHEVAL_LIE_GROUP_TYPES(Base);
  /// Name of the group, for messages.
  static constexpr std::string_view kName = "SE23";

  /// The identity state (R = I, p = 0, v = 0).
  SE23() : position_(Vector3::Zero()), velocity_(Vector3::Zero()) {}

  /// The state (R, p, v).
  SE23(const SO3<Scalar>& rotation, const Vector3& position, const Vector3& velocity)
      : rotation_(rotation), position_(position), velocity_(velocity) {}

  /// The state (R(q), p, v); q is normalised (any non-zero q).
  SE23(const Quaternion& q, const Vector3& position, const Vector3& velocity)
      : rotation_(q), position_(position), velocity_(velocity) {}

  /// The state (R, p, v) from a rotation matrix (precondition as SO3(const Matrix3&)).
  SE23(const Matrix3& rotation, const Vector3& position, const Vector3& velocity)
      : rotation_(rotation), position_(position), velocity_(velocity) {}

  /// The state exp(Hat(τ)) = (Exp(ω), J_l(ω) ρ_p, J_l(ω) ρ_v). Valid for all τ.
  /// J_out_tangent (optional) = RightJacobian(τ).
  static SE23 Exp(const Tangent& tau, Jacobian* J_out_tangent = nullptr) {
    const Vector3 omega = tau.template head<3>();
    const Matrix3 v = SO3<Scalar>::LeftJacobian(omega);
    if (J_out_tangent != nullptr) *J_out_tangent = RightJacobian(tau);
    return SE23(SO3<Scalar>::Exp(omega), v * tau.template segment<3>(3),
                v * tau.template segment<3>(6));
  }

  /// The tangent (ω, ρ_p, ρ_v) with Exp(τ) = *this: |ω| ∈ [0, π], ρ_p = J_l⁻¹(ω) p,
  /// ρ_v = J_l⁻¹(ω) v. Valid for all states (see SO3::Log for θ = π).
  /// J_out_self (optional) = InverseRightJacobian(τ).
  Tangent Log(Jacobian* J_out_self = nullptr) const {
    const Vector3 omega = rotation_.Log();
    const Matrix3 v_inv = SO3<Scalar>::InverseLeftJacobian(omega);
    Tangent tau;
    tau.template head<3>() = omega;
    tau.template segment<3>(3) = v_inv * position_;
    tau.template segment<3>(6) = v_inv * velocity_;
    if (J_out_self != nullptr) *J_out_self = InverseRightJacobian(tau);
    return tau;
  }

  /// The inverse state (Rᵀ, −Rᵀ p, −Rᵀ v). J_out_self (optional) = −Adj().
  SE23 Inverse(Jacobian* J_out_self = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = -Adj();
    const SO3<Scalar> r_inv = rotation_.Inverse();
    return SE23(r_inv, -r_inv.Act(position_), -r_inv.Act(velocity_));
  }

  /// The composition *this · other = (R1 R2, R1 p2 + p1, R1 v2 + v1) (apply other first).
  /// J_out_self (optional) = Adj(other⁻¹); J_out_other (optional) = I.
  SE23 Compose(const SE23& other, Jacobian* J_out_self = nullptr,
               Jacobian* J_out_other = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = other.Inverse().Adj();
    if (J_out_other != nullptr) J_out_other->setIdentity();
    return SE23(rotation_ * other.rotation_, rotation_.Act(other.position_) + position_,
                rotation_.Act(other.velocity_) + velocity_);
  }

  /// The transformed point R x + p, as SE3 with (R, p): the 5x5 matrix applied to [x; 1; 0].
  /// J_out_self (optional) = [−R [x]×, R, 0]; J_out_point (optional) = R.
  Point Act(const Point& x, PointJacobian* J_out_self = nullptr,
            Matrix3* J_out_point = nullptr) const {
    const Matrix3 r = rotation_.Matrix();
    if (J_out_self != nullptr) *J_out_self << -r * detail::Hat3(x), r, Matrix3::Zero();
    if (J_out_point != nullptr) *J_out_point = r;
    return r * x + position_;
  }

  /// The velocity part of the action: R u + v, the 5x5 matrix applied to [u; 0; 1]. For a point
  /// moving with velocity u in the frame of the state, this is its velocity in the world frame
  /// (Galilean velocity addition). J_out_self (optional) = [−R [u]×, 0, R]; J_out_velocity
  /// (optional) = R.
  Vector3 ActVelocity(const Vector3& u, PointJacobian* J_out_self = nullptr,
                      Matrix3* J_out_velocity = nullptr) const {
    const Matrix3 r = rotation_.Matrix();
    if (J_out_self != nullptr) *J_out_self << -r * detail::Hat3(u), Matrix3::Zero(), r;
    if (J_out_velocity != nullptr) *J_out_velocity = r;
    return r * u + velocity_;
  }

  /// The adjoint matrix [[R, 0, 0], [[p]× R, R, 0], [[v]× R, 0, R]] (blocks ω, ρ_p, ρ_v).
  AdjointMatrix Adj() const {
    const Matrix3 r = rotation_.Matrix();
    const Matrix3 zero = Matrix3::Zero();
    AdjointMatrix adj;
    adj << r, zero, zero,                        //
        detail::Hat3(position_) * r, r, zero,  //
        detail::Hat3(velocity_) * r, zero, r;
    return adj;
  }

  /// The 5x5 Lie algebra matrix [[ [ω]×, ρ_p, ρ_v ], [0 0 0], [0 0 0]].
  static MatrixType Hat(const Tangent& tau) {
    MatrixType m = MatrixType::Zero();
    m.template topLeftCorner<3, 3>() = detail::Hat3<Scalar>(tau.template head<3>());
    m.template block<3, 1>(0, 3) = tau.template segment<3>(3);
    m.template block<3, 1>(0, 4) = tau.template segment<3>(6);
    return m;
  }

  /// The tangent of a 5x5 Lie algebra matrix (ω from the skew part of the 3x3 block).
  static Tangent Vee(const MatrixType& m) {
    Tangent tau;
    tau.template head<3>() = detail::Vee3<Scalar>(m.template topLeftCorner<3, 3>());
    tau.template segment<3>(3) = m.template block<3, 1>(0, 3);
    tau.template segment<3>(6) = m.template block<3, 1>(0, 4);
    return tau;
  }

  /// The matrix ad_τ of the Lie bracket, ad_τ ξ = Vee([Hat(τ), Hat(ξ)]):
  /// [[ [ω]×, 0, 0 ], [ [ρ_p]×, [ω]×, 0 ], [ [ρ_v]×, 0, [ω]× ]].
  static AdjointMatrix SmallAdj(const Tangent& tau) {
    const Matrix3 w = detail::Hat3<Scalar>(tau.template head<3>());
    const Matrix3 zero = Matrix3::Zero();
    AdjointMatrix ad;
    ad << w, zero, zero,                                              //
        detail::Hat3<Scalar>(tau.template segment<3>(3)), w, zero,  //
        detail::Hat3<Scalar>(tau.template segment<3>(6)), zero, w;
    return ad;
  }

  /// The 5x5 matrix [[R p v], [0 1 0], [0 0 1]].
  MatrixType Matrix() const {
    MatrixType m = MatrixType::Identity();
    m.template topLeftCorner<3, 3>() = rotation_.Matrix();
    m.template block<3, 1>(0, 3) = position_;
    m.template block<3, 1>(0, 4) = velocity_;
    return m;
  }

  /// The same state with another scalar type (e.g. double → ceres::Jet).
  template <typename NewScalar>
  SE23<NewScalar> Cast() const {
    return SE23<NewScalar>(rotation_.template Cast<NewScalar>(),
                           position_.template cast<NewScalar>(),
                           velocity_.template cast<NewScalar>());
  }

  /// The rotation R.
  const SO3<Scalar>& rotation() const { return rotation_; }
  /// The position p.
  const Vector3& position() const { return position_; }
  /// The velocity v.
  const Vector3& velocity() const { return velocity_; }

  /// Right Jacobian in (ω, ρ_p, ρ_v) order: [[J_r, 0, 0], [Q(−ω, −ρ_p), J_r, 0],
  /// [Q(−ω, −ρ_v), 0, J_r]], J_r = J_r^SO3(ω), with Barfoot's Q (detail::BarfootQ), the SE(3)
  /// structure once for p and once for v. Valid for all τ.
  static Jacobian RightJacobian(const Tangent& tau) {
    const Vector3 omega = tau.template head<3>();
    const Matrix3 jr = SO3<Scalar>::RightJacobian(omega);
    Jacobian j = Jacobian::Zero();
    j.template block<3, 3>(0, 0) = jr;
    j.template block<3, 3>(3, 0) = detail::BarfootQ<Scalar>(-omega, -tau.template segment<3>(3));
    j.template block<3, 3>(3, 3) = jr;
    j.template block<3, 3>(6, 0) = detail::BarfootQ<Scalar>(-omega, -tau.template segment<3>(6));
    j.template block<3, 3>(6, 6) = jr;
    return j;
  }

  /// Inverse right Jacobian (block-triangular inverse of RightJacobian):
  /// [[J_r⁻¹, 0, 0], [−J_r⁻¹ Q_p J_r⁻¹, J_r⁻¹, 0], [−J_r⁻¹ Q_v J_r⁻¹, 0, J_r⁻¹]].
  /// Precondition: |ω| < 2π.
  static Jacobian InverseRightJacobian(const Tangent& tau) {
    const Vector3 omega = tau.template head<3>();
    const Matrix3 jr_inv = SO3<Scalar>::InverseRightJacobian(omega);
    Jacobian j = Jacobian::Zero();
    j.template block<3, 3>(0, 0) = jr_inv;
    j.template block<3, 3>(3, 0) =
        -jr_inv * detail::BarfootQ<Scalar>(-omega, -tau.template segment<3>(3)) * jr_inv;
    j.template block<3, 3>(3, 3) = jr_inv;
    j.template block<3, 3>(6, 0) =
        -jr_inv * detail::BarfootQ<Scalar>(-omega, -tau.template segment<3>(6)) * jr_inv;
    j.template block<3, 3>(6, 6) = jr_inv;
    return j;
  }

 private:
  SO3<Scalar> rotation_;
  Vector3 position_;
  Vector3 velocity_;
};

/// SE_2(3) in double precision.
using SE23d = SE23<double>;

}  // namespace cheval::lie

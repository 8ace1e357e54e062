#pragma once
/// \file
/// SE(3), the group of rigid-body motions T = [R t; 0 1], templated on the scalar so that
/// ceres::Jet passes through.
///
/// | group | storage (order)       | tangent τ (order)     | dim |
/// |-------|-----------------------|-----------------------|-----|
/// | SE3   | (SO3 R, translation t)| (ω, ρ), rotation first| 6   |
///
/// Exp(ω, ρ) = (Exp(ω), V ρ) with V = SO3::LeftJacobian(ω). Note ρ is not the translation: t = V ρ.
/// The conventions for Plus/Minus, Jacobians and Adj are those of lie_group_base.h (right
/// perturbations, optional Jacobian outputs, Adj(g) τ = Vee(g Hat(τ) g⁻¹)). A pose T = T_a_b maps
/// points of frame b to frame a: p_a = R_a_b p_b + t_a_b (t is the origin of b in a). Units:
/// radians and the unit of t (metres in cheval).

#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/lie/detail.h"
#include "cheval/lie/lie_group_base.h"
#include "cheval/lie/so3.h"

namespace cheval::lie {

/// A rigid-body motion (R, t) acting as p ↦ R p + t; tangent (ω, ρ) ∈ R⁶, rotation first.
template <typename T>
class SE3 : public LieGroupBase<SE3<T>, T, 6, 4> {
 public:
  /// The base: the types (Tangent, Jacobian, ...) and the algebra shared by the groups.
  using Base = LieGroupBase<SE3<T>, T, 6, 4>;
  CHEVAL_LIE_GROUP_TYPES(Base);
  /// Name of the group, for messages.
  static constexpr std::string_view kName = "SE3";

  /// The identity motion.
  SE3() : translation_(Vector3::Zero()) {}

  /// The motion (R, t).
  SE3(const SO3<Scalar>& rotation, const Vector3& translation)
      : rotation_(rotation), translation_(translation) {}

  /// The motion (R(q), t); q is normalised (any non-zero q).
  SE3(const Quaternion& q, const Vector3& translation) : rotation_(q), translation_(translation) {}

  /// The motion (R, t) from a rotation matrix (precondition as SO3(const Matrix3&)).
  SE3(const Matrix3& rotation, const Vector3& translation)
      : rotation_(rotation), translation_(translation) {}

  /// The motion exp(Hat(τ)) = (Exp(ω), J_l(ω) ρ). Valid for all τ.
  /// J_out_tangent (optional) = RightJacobian(τ).
  static SE3 Exp(const Tangent& tau, Jacobian* J_out_tangent = nullptr) {
    const Vector3 omega = tau.template head<3>();
    const Vector3 rho = tau.template tail<3>();
    if (J_out_tangent != nullptr) *J_out_tangent = RightJacobian(tau);
    return SE3(SO3<Scalar>::Exp(omega), SO3<Scalar>::LeftJacobian(omega) * rho);
  }

  /// The tangent (ω, ρ) with Exp(τ) = *this, |ω| ∈ [0, π], ρ = J_l⁻¹(ω) t. Valid for all motions
  /// (see SO3::Log for θ = π). J_out_self (optional) = InverseRightJacobian(τ).
  Tangent Log(Jacobian* J_out_self = nullptr) const {
    const Vector3 omega = rotation_.Log();
    Tangent tau;
    tau.template head<3>() = omega;
    tau.template tail<3>() = SO3<Scalar>::InverseLeftJacobian(omega) * translation_;
    if (J_out_self != nullptr) *J_out_self = InverseRightJacobian(tau);
    return tau;
  }

  /// The inverse motion (Rᵀ, −Rᵀ t). J_out_self (optional) = −Adj().
  SE3 Inverse(Jacobian* J_out_self = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = -Adj();
    const SO3<Scalar> r_inv = rotation_.Inverse();
    return SE3(r_inv, -r_inv.Act(translation_));
  }

  /// The composition *this · other = (R1 R2, R1 t2 + t1): other is applied first, so
  /// T_a_c = T_a_b · T_b_c. J_out_self (optional) = Adj(other⁻¹); J_out_other (optional) = I.
  SE3 Compose(const SE3& other, Jacobian* J_out_self = nullptr,
              Jacobian* J_out_other = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = other.Inverse().Adj();
    if (J_out_other != nullptr) J_out_other->setIdentity();
    return SE3(rotation_ * other.rotation_, rotation_.Act(other.translation_) + translation_);
  }

  /// The transformed point R p + t (p_a = T_a_b · p_b).
  /// J_out_self (optional) = [−R [p]×, R]; J_out_point (optional) = R.
  Point Act(const Point& p, PointJacobian* J_out_self = nullptr,
            Matrix3* J_out_point = nullptr) const {
    const Matrix3 r = rotation_.Matrix();
    if (J_out_self != nullptr) *J_out_self << -r * detail::Hat3(p), r;
    if (J_out_point != nullptr) *J_out_point = r;
    return r * p + translation_;
  }

  /// The adjoint matrix [[R, 0], [[t]× R, R]] (rotation-first blocks).
  AdjointMatrix Adj() const {
    const Matrix3 r = rotation_.Matrix();
    AdjointMatrix adj;
    adj << r, Matrix3::Zero(), detail::Hat3(translation_) * r, r;
    return adj;
  }

  /// The 4x4 Lie algebra matrix [[ω]× ρ; 0 0].
  static MatrixType Hat(const Tangent& tau) {
    MatrixType m = MatrixType::Zero();
    m.template topLeftCorner<3, 3>() = detail::Hat3<Scalar>(tau.template head<3>());
    m.template topRightCorner<3, 1>() = tau.template tail<3>();
    return m;
  }

  /// The tangent (ω, ρ) of a 4x4 Lie algebra matrix (ω from the skew part of the 3x3 block).
  static Tangent Vee(const MatrixType& m) {
    Tangent tau;
    tau.template head<3>() = detail::Vee3<Scalar>(m.template topLeftCorner<3, 3>());
    tau.template tail<3>() = m.template topRightCorner<3, 1>();
    return tau;
  }

  /// The matrix ad_τ of the Lie bracket, ad_τ ξ = Vee([Hat(τ), Hat(ξ)]) = [[ω]×, 0; [ρ]×, [ω]×] ξ.
  static AdjointMatrix SmallAdj(const Tangent& tau) {
    const Matrix3 w = detail::Hat3<Scalar>(tau.template head<3>());
    AdjointMatrix ad;
    ad << w, Matrix3::Zero(), detail::Hat3<Scalar>(tau.template tail<3>()), w;
    return ad;
  }

  /// The homogeneous 4x4 matrix [R t; 0 1].
  MatrixType Matrix() const {
    MatrixType m = MatrixType::Identity();
    m.template topLeftCorner<3, 3>() = rotation_.Matrix();
    m.template topRightCorner<3, 1>() = translation_;
    return m;
  }

  /// The same motion with another scalar type (e.g. double → ceres::Jet).
  template <typename NewScalar>
  SE3<NewScalar> Cast() const {
    return SE3<NewScalar>(rotation_.template Cast<NewScalar>(),
                          translation_.template cast<NewScalar>());
  }

  /// The rotation R.
  const SO3<Scalar>& rotation() const { return rotation_; }
  /// The translation t.
  const Vector3& translation() const { return translation_; }

  /// Right Jacobian in (ω, ρ) order: [[J_r(ω), 0], [Q(−ω, −ρ), J_r(ω)]] with Barfoot's Q
  /// (detail::BarfootQ; J_r(τ) = J_l(−τ)). Exp(τ + δ) ≈ Exp(τ) Exp(J_r(τ) δ). Valid for all τ.
  static Jacobian RightJacobian(const Tangent& tau) {
    const Vector3 omega = tau.template head<3>();
    const Vector3 rho = tau.template tail<3>();
    const Matrix3 jr = SO3<Scalar>::RightJacobian(omega);
    Jacobian j;
    j << jr, Matrix3::Zero(), detail::BarfootQ<Scalar>(-omega, -rho), jr;
    return j;
  }

  /// Inverse right Jacobian [[J_r⁻¹, 0], [−J_r⁻¹ Q J_r⁻¹, J_r⁻¹]] (block-triangular inverse of
  /// RightJacobian). Precondition: |ω| < 2π.
  static Jacobian InverseRightJacobian(const Tangent& tau) {
    const Vector3 omega = tau.template head<3>();
    const Vector3 rho = tau.template tail<3>();
    const Matrix3 jr_inv = SO3<Scalar>::InverseRightJacobian(omega);
    Jacobian j;
    j << jr_inv, Matrix3::Zero(), -jr_inv * detail::BarfootQ<Scalar>(-omega, -rho) * jr_inv, jr_inv;
    return j;
  }

 private:
  SO3<Scalar> rotation_;
  Vector3 translation_;
};

/// SE(3) in double precision.
using SE3d = SE3<double>;

}  // namespace cheval::lie

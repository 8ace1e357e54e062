#pragma once
/// \file
/// Sim(3), the group of similarity transforms S = [sR t; 0 1] (rotation, translation, positive
/// scale), templated on the scalar so that ceres::Jet passes through.
///
/// | group | storage (order)                  | tangent τ (order)                | dim |
/// |-------|----------------------------------|----------------------------------|-----|
/// | Sim3  | (SO3 R, translation t, scale s)  | (ω, ρ, σ = log s), rotation first| 7   |
///
/// Exp(ω, ρ, σ) = (Exp(ω), W ρ, e^σ) with W = ∫₀¹ e^(uσ) Exp(uω) du = a0 I + a1 [ω]× + a2 [ω]×²,
/// the closed form of E. Eade, "Lie Groups for 2D and 3D Transformations" (Sim(3) section), with
/// F(z) = (e^z − 1)/z at z = σ and z = σ + iθ (detail::ComputeSim3Coefficients). The right Jacobian
/// is analytic (closed form, no series in ad): see RightJacobian. The conventions for Plus/Minus,
/// Jacobians and Adj are those of lie_group_base.h. S = S_a_b maps p_b to p_a = s R p_b + t.
/// Units: radians, the unit of t, and σ dimensionless. Valid for |σ| < 700 (e^σ must not
/// overflow).

#include <sstream>
#include <string_view>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "cheval/common/error.h"
#include "cheval/lie/detail.h"
#include "cheval/lie/lie_group_base.h"
#include "cheval/lie/so3.h"

namespace cheval::lie {

/// A similarity (R, t, s) acting as p ↦ s R p + t; tangent (ω, ρ, σ) ∈ R⁷, rotation first.
template <typename T>
class Sim3 : public LieGroupBase<Sim3<T>, T, 7, 4> {
 public:
  /// The base: the types (Tangent, Jacobian, ...) and the algebra shared by the groups.
  using Base = LieGroupBase<Sim3<T>, T, 7, 4>;
  CHEVAL_LIE_GROUP_TYPES(Base);
  /// Name of the group, for messages.
  static constexpr std::string_view kName = "Sim3";

  /// The identity similarity.
  Sim3() : translation_(Vector3::Zero()), scale_(Scalar(1)) {}

  /// The similarity (R, t, s). Throws cheval::ComputeError unless s > 0 (NaN included).
  Sim3(const SO3<Scalar>& rotation, const Vector3& translation, const Scalar& scale)
      : rotation_(rotation), translation_(translation), scale_(CheckedScale(scale)) {}

  /// The similarity (R(q), t, s); q is normalised. Throws cheval::ComputeError unless s > 0.
  Sim3(const Quaternion& q, const Vector3& translation, const Scalar& scale)
      : Sim3(SO3<Scalar>(q), translation, scale) {}

  /// The similarity (R, t, s) from a rotation matrix (precondition as SO3(const Matrix3&)).
  /// Throws cheval::ComputeError unless s > 0.
  Sim3(const Matrix3& rotation, const Vector3& translation, const Scalar& scale)
      : Sim3(SO3<Scalar>(rotation), translation, scale) {}

  /// The similarity exp(Hat(τ)) = (Exp(ω), W(ω, σ) ρ, e^σ). Valid for all ω and |σ| < 700.
  /// J_out_tangent (optional) = RightJacobian(τ).
  static Sim3 Exp(const Tangent& tau, Jacobian* J_out_tangent = nullptr) {
    using std::exp;
    const Vector3 omega = tau.template head<3>();
    const Vector3 rho = tau.template segment<3>(3);
    const Scalar sigma = tau[6];
    if (J_out_tangent != nullptr) *J_out_tangent = RightJacobian(tau);
    return Sim3(SO3<Scalar>::Exp(omega), WMatrix(omega, sigma) * rho, exp(sigma));
  }

  /// The tangent (ω, ρ, σ) with Exp(τ) = *this: ω = Log(R) (|ω| ≤ π), σ = log s, ρ = W⁻¹ t.
  /// W is invertible for |ω| < 2π. J_out_self (optional) = InverseRightJacobian(τ).
  Tangent Log(Jacobian* J_out_self = nullptr) const {
    using std::log;
    const Vector3 omega = rotation_.Log();
    const Scalar sigma = log(scale_);
    Tangent tau;
    tau.template head<3>() = omega;
    tau.template segment<3>(3) = WMatrix(omega, sigma).inverse() * translation_;
    tau[6] = sigma;
    if (J_out_self != nullptr) *J_out_self = InverseRightJacobian(tau);
    return tau;
  }

  /// The inverse similarity (Rᵀ, −Rᵀ t / s, 1/s). J_out_self (optional) = −Adj().
  Sim3 Inverse(Jacobian* J_out_self = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = -Adj();
    const SO3<Scalar> r_inv = rotation_.Inverse();
    return Sim3(r_inv, -r_inv.Act(translation_) / scale_, Scalar(1) / scale_);
  }

  /// The composition *this · other = (R1 R2, s1 R1 t2 + t1, s1 s2) (apply other first).
  /// J_out_self (optional) = Adj(other⁻¹); J_out_other (optional) = I.
  Sim3 Compose(const Sim3& other, Jacobian* J_out_self = nullptr,
               Jacobian* J_out_other = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = other.Inverse().Adj();
    if (J_out_other != nullptr) J_out_other->setIdentity();
    return Sim3(rotation_ * other.rotation_,
                scale_ * rotation_.Act(other.translation_) + translation_, scale_ * other.scale_);
  }

  /// The transformed point s R p + t.
  /// J_out_self (optional) = [−s R [p]×, s R, s R p]; J_out_point (optional) = s R.
  Point Act(const Point& p, PointJacobian* J_out_self = nullptr,
            Matrix3* J_out_point = nullptr) const {
    const Matrix3 sr = scale_ * rotation_.Matrix();
    const Point sr_p = sr * p;
    if (J_out_self != nullptr) *J_out_self << -sr * detail::Hat3(p), sr, sr_p;
    if (J_out_point != nullptr) *J_out_point = sr;
    return sr_p + translation_;
  }

  /// The adjoint matrix [[R, 0, 0], [[t]× R, s R, −t], [0, 0, 1]] (blocks ω, ρ, σ).
  AdjointMatrix Adj() const {
    const Matrix3 r = rotation_.Matrix();
    AdjointMatrix adj = AdjointMatrix::Zero();
    adj.template block<3, 3>(0, 0) = r;
    adj.template block<3, 3>(3, 0) = detail::Hat3(translation_) * r;
    adj.template block<3, 3>(3, 3) = scale_ * r;
    adj.template block<3, 1>(3, 6) = -translation_;
    adj(6, 6) = Scalar(1);
    return adj;
  }

  /// The 4x4 Lie algebra matrix [[ω]× + σ I, ρ; 0 0].
  static MatrixType Hat(const Tangent& tau) {
    MatrixType m = MatrixType::Zero();
    m.template topLeftCorner<3, 3>() =
        detail::Hat3<Scalar>(tau.template head<3>()) + tau[6] * Matrix3::Identity();
    m.template topRightCorner<3, 1>() = tau.template segment<3>(3);
    return m;
  }

  /// The tangent of a 4x4 Lie algebra matrix: ω from the skew part of the 3x3 block, σ its mean
  /// diagonal, ρ the last column.
  static Tangent Vee(const MatrixType& m) {
    Tangent tau;
    tau.template head<3>() = detail::Vee3<Scalar>(m.template topLeftCorner<3, 3>());
    tau.template segment<3>(3) = m.template topRightCorner<3, 1>();
    tau[6] = m.template topLeftCorner<3, 3>().trace() / Scalar(3);
    return tau;
  }

  /// The matrix ad_τ of the Lie bracket, ad_τ ξ = Vee([Hat(τ), Hat(ξ)]):
  /// [[ [ω]×, 0, 0 ], [ [ρ]×, [ω]× + σ I, −ρ ], [0, 0, 0]].
  static AdjointMatrix SmallAdj(const Tangent& tau) {
    const Matrix3 w = detail::Hat3<Scalar>(tau.template head<3>());
    AdjointMatrix ad = AdjointMatrix::Zero();
    ad.template block<3, 3>(0, 0) = w;
    ad.template block<3, 3>(3, 0) = detail::Hat3<Scalar>(tau.template segment<3>(3));
    ad.template block<3, 3>(3, 3) = w + tau[6] * Matrix3::Identity();
    ad.template block<3, 1>(3, 6) = -tau.template segment<3>(3);
    return ad;
  }

  /// The homogeneous 4x4 matrix [s R t; 0 1].
  MatrixType Matrix() const {
    MatrixType m = MatrixType::Identity();
    m.template topLeftCorner<3, 3>() = scale_ * rotation_.Matrix();
    m.template topRightCorner<3, 1>() = translation_;
    return m;
  }

  /// The same similarity with another scalar type (e.g. double → ceres::Jet).
  template <typename NewScalar>
  Sim3<NewScalar> Cast() const {
    return Sim3<NewScalar>(rotation_.template Cast<NewScalar>(),
                           translation_.template cast<NewScalar>(), NewScalar(scale_));
  }

  /// The rotation R.
  const SO3<Scalar>& rotation() const { return rotation_; }
  /// The translation t.
  const Vector3& translation() const { return translation_; }
  /// The scale s > 0.
  const Scalar& scale() const { return scale_; }

  /// The matrix W(ω, σ) = Σ_k Hat₃(ω, σ)^k/(k+1)! = ∫₀¹ e^(uσ) Exp(uω) du of the exponential,
  /// t = W ρ, where Hat₃ = [ω]× + σ I is the 3x3 block of Hat(τ).
  static Matrix3 WMatrix(const Vector3& omega, const Scalar& sigma) {
    const detail::Sim3Coefficients<Scalar> c =
        detail::ComputeSim3Coefficients(omega.squaredNorm(), sigma);
    const Matrix3 k = detail::Hat3(omega);
    return c.a0 * Matrix3::Identity() + c.a1 * k + c.a2 * k * k;
  }

  /// Right Jacobian, Exp(τ + δ) ≈ Exp(τ) Exp(J_r(τ) δ), in closed form: with (R, t, s) = Exp(τ)
  /// and t = W(ω, σ) ρ, the perturbation of Exp(τ) on the right is (J_r^SO3(ω) δω, (sR)⁻¹ dt, δσ),
  /// so J_r = [[J_r^SO3(ω), 0, 0], [(sR)⁻¹ ∂(Wρ)/∂ω, (sR)⁻¹ W, (sR)⁻¹ (∂W/∂σ) ρ], [0, 0, 1]] where
  ///   ∂(Wρ)/∂ω = 2 a1' (ω×ρ) ωᵀ − a1 [ρ]× + 2 a2' (ω×(ω×ρ)) ωᵀ + a2 ((ω·ρ) I + ω ρᵀ − 2 ρ ωᵀ)
  /// and ' is ∂/∂(θ²) (detail::ComputeSim3Coefficients). Valid for all ω and |σ| < 700; it equals
  /// the series Σ_k (−ad_τ)^k/(k+1)! (checked in the tests).
  static Jacobian RightJacobian(const Tangent& tau) {
    using std::exp;
    const Vector3 omega = tau.template head<3>();
    const Vector3 rho = tau.template segment<3>(3);
    const Scalar sigma = tau[6];
    const detail::Sim3Coefficients<Scalar> c =
        detail::ComputeSim3Coefficients(omega.squaredNorm(), sigma);
    const Matrix3 k = detail::Hat3(omega);
    const Matrix3 k_sq = k * k;
    const Matrix3 w = c.a0 * Matrix3::Identity() + c.a1 * k + c.a2 * k_sq;
    const Matrix3 dw_dsigma =
        c.da0_dsigma * Matrix3::Identity() + c.da1_dsigma * k + c.da2_dsigma * k_sq;
    const Vector3 w_x_rho = omega.cross(rho);
    const Vector3 w_x_w_x_rho = omega.cross(w_x_rho);
    const Matrix3 d_wrho_d_omega =
        Scalar(2) * c.da1_dtheta_sq * w_x_rho * omega.transpose() - c.a1 * detail::Hat3(rho) +
        Scalar(2) * c.da2_dtheta_sq * w_x_w_x_rho * omega.transpose() +
        c.a2 * (omega.dot(rho) * Matrix3::Identity() + omega * rho.transpose() -
                Scalar(2) * rho * omega.transpose());
    // (sR)⁻¹ = e^(−σ) Exp(−ω).
    const Matrix3 sr_inv = exp(-sigma) * SO3<Scalar>::Exp(-omega).Matrix();
    Jacobian j = Jacobian::Zero();
    j.template block<3, 3>(0, 0) = SO3<Scalar>::RightJacobian(omega);
    j.template block<3, 3>(3, 0) = sr_inv * d_wrho_d_omega;
    j.template block<3, 3>(3, 3) = sr_inv * w;
    j.template block<3, 1>(3, 6) = sr_inv * (dw_dsigma * rho);
    j(6, 6) = Scalar(1);
    return j;
  }

  /// Inverse right Jacobian, the block-triangular inverse of RightJacobian:
  /// [[J11⁻¹, 0, 0], [−J22⁻¹ J21 J11⁻¹, J22⁻¹, −J22⁻¹ J23], [0, 0, 1]]. Precondition: |ω| < 2π.
  static Jacobian InverseRightJacobian(const Tangent& tau) {
    const Jacobian jr = RightJacobian(tau);
    const Matrix3 j11_inv = SO3<Scalar>::InverseRightJacobian(tau.template head<3>());
    const Matrix3 j22_inv = jr.template block<3, 3>(3, 3).inverse();
    Jacobian j = Jacobian::Zero();
    j.template block<3, 3>(0, 0) = j11_inv;
    j.template block<3, 3>(3, 0) = -j22_inv * jr.template block<3, 3>(3, 0) * j11_inv;
    j.template block<3, 3>(3, 3) = j22_inv;
    j.template block<3, 1>(3, 6) = -j22_inv * jr.template block<3, 1>(3, 6);
    j(6, 6) = Scalar(1);
    return j;
  }

 private:
  static const Scalar& CheckedScale(const Scalar& scale) {
    if (!(scale > Scalar(0))) {
      std::ostringstream message;
      message.precision(17);
      message << "Sim3: the scale must be positive";
      if constexpr (std::is_arithmetic_v<Scalar>) message << ", got " << scale;
      throw ComputeError(message.str());
    }
    return scale;
  }

  SO3<Scalar> rotation_;
  Vector3 translation_;
  Scalar scale_;
};

/// Sim(3) in double precision.
using Sim3d = Sim3<double>;

}  // namespace cheval::lie

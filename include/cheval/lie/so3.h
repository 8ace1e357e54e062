#pragma once
/// \file
/// SO(3), the group of 3D rotations, templated on the scalar so that ceres::Jet passes through.
///
/// | group | storage                                    | tangent τ (order)   | dim |
/// |-------|--------------------------------------------|---------------------|-----|
/// | SO3   | unit quaternion q (Eigen order x, y, z, w) | ω (rotation vector) | 3   |
///
/// (docs/lie.md has the table for all four groups: rotation always comes first.) Plus, Minus,
/// Between, the left Jacobians and the conventions shared by all groups are in lie_group_base.h.
///
/// A rotation R = R_a_b maps coordinates in frame b to frame a: p_a = R_a_b p_b. Angles in radians.

#include <cmath>
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/lie/detail.h"
#include "cheval/lie/lie_group_base.h"

namespace cheval::lie {

/// A 3D rotation stored as a unit quaternion; tangent ω ∈ R³ (axis · angle, radians).
template <typename T>
class SO3 : public LieGroupBase<SO3<T>, T, 3, 3> {
 public:
  /// The base: the types (Tangent, Jacobian, ...) and the algebra shared by the groups.
  using Base = LieGroupBase<SO3<T>, T, 3, 3>;
  CHEVAL_LIE_GROUP_TYPES(Base);
  /// Name of the group, for messages.
  static constexpr std::string_view kName = "SO3";

  /// The identity rotation.
  SO3() : q_(Quaternion::Identity()) {}

  /// The rotation of quaternion q, normalised (any non-zero q; q and −q give the same rotation).
  explicit SO3(const Quaternion& q) : q_(Normalized(q)) {}

  /// The rotation of the matrix r. Precondition: r is a rotation (orthonormal, det +1); a slightly
  /// non-orthonormal r gives the unit quaternion of Shepperd's method (largest-pivot branch)
  /// normalised, a nearby rotation.
  explicit SO3(const Matrix3& r) : q_(Normalized(QuaternionFromMatrix(r))) {}

  /// The rotation exp([ω]×) = Rodrigues' formula, by angle |ω| about ω/|ω| (any |ω|).
  /// J_out_tangent (optional) = RightJacobian(ω).
  static SO3 Exp(const Tangent& omega, Jacobian* J_out_tangent = nullptr) {
    const detail::HalfAngle<Scalar> h = detail::ComputeHalfAngle(omega.squaredNorm());
    SO3 result;
    result.q_ = Quaternion(h.cos_half, h.sin_half_by_th * omega.x(), h.sin_half_by_th * omega.y(),
                           h.sin_half_by_th * omega.z());
    if (J_out_tangent != nullptr) *J_out_tangent = RightJacobian(omega);
    return result;
  }

  /// The rotation vector ω with |ω| = θ ∈ [0, π] and Exp(ω) = *this. Valid for all rotations: it is
  /// computed from the quaternion as θ = 2 atan2(|v|, |w|), which stays accurate near θ = π; at
  /// exactly θ = π either of ±ω may be returned. J_out_self (optional) = InverseRightJacobian(ω).
  Tangent Log(Jacobian* J_out_self = nullptr) const {
    Scalar w = q_.w();
    Tangent v = q_.vec();
    if (w < Scalar(0)) {  // q and −q are the same rotation; pick w ≥ 0 so that θ ≤ π
      w = -w;
      v = -v;
    }
    const Tangent omega = detail::ComputeAngleOverSinHalf(w, v.squaredNorm()) * v;
    if (J_out_self != nullptr) *J_out_self = InverseRightJacobian(omega);
    return omega;
  }

  /// The inverse rotation R⁻¹ = Rᵀ. J_out_self (optional) = −Adj().
  SO3 Inverse(Jacobian* J_out_self = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = -Adj();
    SO3 result;
    result.q_ = q_.conjugate();
    return result;
  }

  /// The composition *this · other (apply other first). The quaternion product is re-normalised.
  /// J_out_self (optional) = Adj(other⁻¹) = otherᵀ as a matrix; J_out_other (optional) = I.
  SO3 Compose(const SO3& other, Jacobian* J_out_self = nullptr,
              Jacobian* J_out_other = nullptr) const {
    if (J_out_self != nullptr) *J_out_self = other.Matrix().transpose();
    if (J_out_other != nullptr) J_out_other->setIdentity();
    SO3 result;
    result.q_ = Normalized(q_ * other.q_);
    return result;
  }

  /// The rotated point R p (p in the frame on the right of R, result in the frame on the left).
  /// J_out_self (optional) = −R [p]×; J_out_point (optional) = R.
  Point Act(const Point& p, PointJacobian* J_out_self = nullptr,
            Matrix3* J_out_point = nullptr) const {
    const Matrix3 r = Matrix();
    if (J_out_self != nullptr) *J_out_self = -r * detail::Hat3(p);
    if (J_out_point != nullptr) *J_out_point = r;
    return r * p;
  }

  /// The adjoint matrix, Adj(g) ω = R ω for SO(3).
  AdjointMatrix Adj() const { return Matrix(); }

  /// The skew-symmetric matrix [ω]× with [ω]× p = ω × p.
  static MatrixType Hat(const Tangent& omega) { return detail::Hat3(omega); }

  /// The vector of a skew-symmetric matrix (of its skew-symmetric part (m − mᵀ)/2).
  static Tangent Vee(const MatrixType& m) { return detail::Vee3<Scalar>(m); }

  /// The matrix ad_ω of the Lie bracket, ad_ω ξ = Vee([Hat(ω), Hat(ξ)]) = [ω]× ξ.
  static AdjointMatrix SmallAdj(const Tangent& omega) { return detail::Hat3(omega); }

  /// The 3x3 rotation matrix R.
  MatrixType Matrix() const { return q_.toRotationMatrix(); }

  /// The same rotation with another scalar type (e.g. double → ceres::Jet, double → float).
  template <typename NewScalar>
  SO3<NewScalar> Cast() const {
    return SO3<NewScalar>(q_.template cast<NewScalar>());
  }

  /// The unit quaternion (coefficients x, y, z, w in Eigen's storage order).
  const Quaternion& quaternion() const { return q_; }

  /// Right Jacobian J_r(ω) = I − A [ω]× + B [ω]×², A = (1 − cos θ)/θ², B = (θ − sin θ)/θ³;
  /// Exp(ω + δ) ≈ Exp(ω) Exp(J_r(ω) δ). Valid for all ω.
  static Jacobian RightJacobian(const Tangent& omega) {
    const detail::RotationCoefficients<Scalar> c =
        detail::ComputeRotationCoefficients(omega.squaredNorm());
    const Matrix3 k = detail::Hat3(omega);
    return Matrix3::Identity() - c.a * k + c.b * k * k;
  }

  /// Inverse right Jacobian J_r⁻¹(ω) = I + ½[ω]× + D [ω]×², D = 1/θ² − cos(θ/2)/(2θ sin(θ/2)).
  /// Precondition: θ = |ω| < 2π (J_r is singular at 2π); Log returns θ ≤ π.
  static Jacobian InverseRightJacobian(const Tangent& omega) {
    const Scalar d = detail::ComputeInverseJacobianCoefficient(omega.squaredNorm());
    const Matrix3 k = detail::Hat3(omega);
    return Matrix3::Identity() + Scalar(0.5) * k + d * k * k;
  }

 private:
  static Quaternion Normalized(const Quaternion& q) {
    using std::sqrt;
    return Quaternion(q.coeffs() / sqrt(q.coeffs().squaredNorm()));
  }

  // Shepperd's method: the largest of 4w², 4x², 4y², 4z² is taken under the square root.
  static Quaternion QuaternionFromMatrix(const Matrix3& r) {
    using std::sqrt;
    const Scalar trace = r.trace();
    if (trace >= r(0, 0) && trace >= r(1, 1) && trace >= r(2, 2)) {
      const Scalar root = sqrt(Scalar(1) + trace);  // 2|w|
      const Scalar f = Scalar(0.5) / root;
      return Quaternion(Scalar(0.5) * root, (r(2, 1) - r(1, 2)) * f, (r(0, 2) - r(2, 0)) * f,
                        (r(1, 0) - r(0, 1)) * f);
    }
    int i = 0;
    if (r(1, 1) > r(0, 0)) i = 1;
    if (r(2, 2) > r(i, i)) i = 2;
    const int j = (i + 1) % 3;
    const int k = (j + 1) % 3;
    const Scalar root = sqrt(Scalar(1) + r(i, i) - r(j, j) - r(k, k));  // 2|q_i|
    const Scalar f = Scalar(0.5) / root;
    Tangent v;
    v[i] = Scalar(0.5) * root;
    v[j] = (r(j, i) + r(i, j)) * f;
    v[k] = (r(k, i) + r(i, k)) * f;
    return Quaternion(Scalar((r(k, j) - r(j, k)) * f), v.x(), v.y(), v.z());
  }

  Quaternion q_;
};

/// SO(3) in double precision.
using SO3d = SO3<double>;

}  // namespace cheval::lie

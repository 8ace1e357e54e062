#pragma once
/// \file
/// LieGroupBase: the part of the API of SO3, SE3, Sim3 and SE23 that follows from each group's own
/// Exp, Log, Inverse, Compose, Adj and right Jacobian, written once for all four (a CRTP base, the
/// pattern of manif's LieGroupBase and Sophus' SO3Base): the types, Identity, operator*, right
/// Plus and Minus, Between, the left Jacobians, and the Jacobians of Plus, Minus and Between.
///
/// Conventions shared by all cheval::lie groups (docs/lie.md has the full reference):
/// - Exp(τ) = exp(Hat(τ)); Log is its inverse with rotation angle θ = |ω| ∈ [0, π].
/// - Right perturbations: g ⊕ τ = g · Exp(τ) (Plus) and h ⊖ g = Log(g⁻¹ · h) (Minus).
/// - Jacobians are optional outputs (nullptr = not wanted) named J_out_in and defined on the right:
///   for f: G → H, J = ∂(f(g ⊕ δ) ⊖ f(g))/∂δ at δ = 0; for a vector result, ∂f(g ⊕ δ)/∂δ; for a
///   vector argument, the ordinary derivative. The right Jacobian J_r(τ) is defined by
///   Exp(τ + δ) ≈ Exp(τ) Exp(J_r(τ) δ), the left one by Exp(τ + δ) ≈ Exp(J_l(τ) δ) Exp(τ).
/// - Adj(g) τ = Vee(g Hat(τ) g⁻¹), so g Exp(τ) = Exp(Adj(g) τ) g.
/// - Rotation comes first, in storage and in the tangent (ω, ...).
/// - Small angles use Taylor series in θ² below a threshold (not only at θ = 0), so values and Jet
///   derivatives are finite and accurate everywhere; see detail.h.

#include <Eigen/Core>
#include <Eigen/Geometry>

/// Declares, inside a group class, the types of its LieGroupBase `Base` (Scalar, Tangent, Point,
/// Vector3, Jacobian, PointJacobian, Matrix3, MatrixType, AdjointMatrix, Quaternion) for its own
/// body: the members of a dependent base are not found by unqualified lookup. (manif's
/// MANIF_GROUP_TYPEDEFS and Eigen's EIGEN_DENSE_PUBLIC_INTERFACE do the same.)
#define CHEVAL_LIE_GROUP_TYPES(Base)                                                             \
  using typename Base::Scalar, typename Base::Tangent, typename Base::Point,                    \
      typename Base::Vector3, typename Base::Jacobian, typename Base::PointJacobian,             \
      typename Base::Matrix3, typename Base::MatrixType, typename Base::AdjointMatrix,           \
      typename Base::Quaternion

namespace cheval::lie {

/// Base of the group `Derived` (SO3<T>, SE3<T>, Sim3<T>, SE23<T>) with scalar T (double, float or
/// ceres::Jet), `DoF` tangent dimensions and `MatrixDim` x `MatrixDim` matrices.
///
/// `Derived` provides, with these exact signatures (each Jacobian argument defaulting to nullptr):
///   - a default constructor that makes the identity;
///   - `static Derived Exp(const Tangent&, Jacobian* J_out_tangent)`;
///   - `Tangent Log(Jacobian* J_out_self) const`;
///   - `Derived Inverse(Jacobian* J_out_self) const`;
///   - `Derived Compose(const Derived&, Jacobian* J_out_self, Jacobian* J_out_other) const`;
///   - `AdjointMatrix Adj() const`;
///   - `static Jacobian RightJacobian(const Tangent&)` and `InverseRightJacobian(const Tangent&)`.
/// Everything here is composed of those; nothing here stores data.
template <typename Derived, typename T, int DoF, int MatrixDim>
class LieGroupBase {
 public:
  /// The scalar type (double, float or ceres::Jet).
  using Scalar = T;
  /// Tangent dimension (degrees of freedom).
  static constexpr int kDoF = DoF;
  /// Size of the square matrix returned by Matrix().
  static constexpr int kMatrixDim = MatrixDim;

  /// Tangent vector, rotation vector ω (radians) first; the table in docs/lie.md gives the rest.
  using Tangent = Eigen::Matrix<Scalar, kDoF, 1>;
  /// A 3D point or vector.
  using Point = Eigen::Matrix<Scalar, 3, 1>;
  /// 3-vector.
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  /// Jacobian of a group or tangent result with respect to a group or tangent argument.
  using Jacobian = Eigen::Matrix<Scalar, kDoF, kDoF>;
  /// Jacobian of a point (or velocity) result with respect to the group.
  using PointJacobian = Eigen::Matrix<Scalar, 3, kDoF>;
  /// 3x3 matrix.
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  /// Matrix of the group element, kMatrixDim x kMatrixDim.
  using MatrixType = Eigen::Matrix<Scalar, kMatrixDim, kMatrixDim>;
  /// Matrix of the (group or Lie algebra) adjoint.
  using AdjointMatrix = Eigen::Matrix<Scalar, kDoF, kDoF>;
  /// Quaternion type of the rotation.
  using Quaternion = Eigen::Quaternion<Scalar>;

  /// The identity element.
  static Derived Identity() { return Derived(); }

  /// The composition *this · other (apply other first); same as Compose(other).
  Derived operator*(const Derived& other) const { return derived().Compose(other); }

  /// Right plus g ⊕ τ = g · Exp(τ). J_out_self (optional) = Adj(Exp(τ))⁻¹ = Adj(Exp(−τ)), the
  /// Jacobian of Compose with respect to g; J_out_tangent (optional) = RightJacobian(τ), that of
  /// Exp.
  Derived Plus(const Tangent& tau, Jacobian* J_out_self = nullptr,
               Jacobian* J_out_tangent = nullptr) const {
    return derived().Compose(Derived::Exp(tau, J_out_tangent), J_out_self);
  }

  /// Right minus g ⊖ other = Log(other⁻¹ · g) = Log(other.Between(g)), the tangent from other to
  /// *this in the frame of other, so other ⊕ (g ⊖ other) = g. J_out_self (optional) = J_r⁻¹(τ);
  /// J_out_other (optional) = −J_r⁻¹(−τ) (= −J_l⁻¹(τ)).
  Tangent Minus(const Derived& other, Jacobian* J_out_self = nullptr,
                Jacobian* J_out_other = nullptr) const {
    const Tangent tau = other.Between(derived()).Log();
    if (J_out_self != nullptr) *J_out_self = Derived::InverseRightJacobian(tau);
    if (J_out_other != nullptr) *J_out_other = -Derived::InverseRightJacobian(-tau);
    return tau;
  }

  /// The relative element *this⁻¹ · other (g_a_b.Between(g_a_c) = g_b_c), so
  /// Compose(Between(other)) = other. J_out_self (optional) = −Adj(result⁻¹);
  /// J_out_other (optional) = I.
  Derived Between(const Derived& other, Jacobian* J_out_self = nullptr,
                  Jacobian* J_out_other = nullptr) const {
    const Derived result = derived().Inverse().Compose(other, nullptr, J_out_other);
    if (J_out_self != nullptr) *J_out_self = -result.Inverse().Adj();
    return result;
  }

  /// Left Jacobian J_l(τ) = J_r(−τ) = Adj(Exp(τ)) J_r(τ); Exp(τ + δ) ≈ Exp(J_l(τ) δ) Exp(τ).
  /// For SO3 it is also the matrix V of the SE(3) exponential, t = V ρ.
  static Jacobian LeftJacobian(const Tangent& tau) { return Derived::RightJacobian(-tau); }

  /// Inverse left Jacobian J_l⁻¹(τ) = J_r⁻¹(−τ). Precondition: |ω| < 2π.
  static Jacobian InverseLeftJacobian(const Tangent& tau) {
    return Derived::InverseRightJacobian(-tau);
  }

 protected:
  LieGroupBase() = default;

 private:
  const Derived& derived() const { return static_cast<const Derived&>(*this); }
};

}  // namespace cheval::lie

#pragma once
/// \file
/// The interface every kind of synthetic motion implements (docs/sim.md, "The kinds"), and the small
/// jet geometry the kinds share. Internal to src/sim.

#include <array>
#include <cstdint>
#include <memory>
#include <numbers>

#include "cheval/sim/motion.h"
#include "jet.h"

namespace cheval {
class Random;
}

namespace cheval::sim::internal {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

template <class T>
using Vec3 = std::array<T, 3>;
template <class T>
using Mat3 = std::array<std::array<T, 3>, 3>;  // row-major: m[row][column]

/// R_world_body = Rz(yaw) Ry(pitch) Rx(roll) (body x forward, y left, z up; pitch > 0 is nose down).
Mat3<Jet> RotationZYX(const Jet& yaw, const Jet& pitch, const Jet& roll);

/// One kind of motion with its random parameters fixed: the position is
/// p(t) = ∫₀ᵗ u(τ) dτ + q(t) with the integrand u (only when integrated()) and the closed-form
/// offset q, the orientation R_world_body(t) = Attitude(p, t). Every member is a closed form of t, so
/// evaluated on Jet::Variable(t) it carries the exact derivatives (src/sim/internal/jet.h); the
/// integral is the caller's (MotionModel: Gauss–Legendre quadrature). Immutable after construction.
class Shape {
 public:
  virtual ~Shape() = default;

  /// Whether p has the integral part. When false, u is zero and Integrand is never called.
  virtual bool integrated() const = 0;
  /// u(t), world frame, m/s: as a number (for the quadrature) and as a jet (the derivatives of ∫u).
  /// Both evaluate the same formula, the first in plain double arithmetic.
  virtual Vec3<double> Integrand(double t) const = 0;
  virtual Vec3<Jet> Integrand(const Jet& t) const = 0;
  /// q(t), world frame, m.
  virtual Vec3<Jet> Offset(const Jet& t) const = 0;
  /// R_world_body at t, given the whole position jet p(t) (the drone tilts along p'').
  virtual Mat3<Jet> Attitude(const Vec3<Jet>& p, const Jet& t) const = 0;
};

/// A Shape with an integral part whose u is one template `IntegrandAt<T>(t)` of the derived class,
/// instantiated for double and for Jet (so the two Integrand overloads cannot disagree).
template <class Derived>
class IntegratedShape : public Shape {
 public:
  bool integrated() const final { return true; }
  Vec3<double> Integrand(double t) const final { return static_cast<const Derived&>(*this).IntegrandAt(t); }
  Vec3<Jet> Integrand(const Jet& t) const final { return static_cast<const Derived&>(*this).IntegrandAt(t); }
};

/// The kinds (src/sim/shapes/*.cc). Each draws its parameters from `random` in a fixed order.
std::unique_ptr<const Shape> MakeCar(Random& random);
std::unique_ptr<const Shape> MakeLegged(Random& random);
std::unique_ptr<const Shape> MakeDrone(Random& random);
std::unique_ptr<const Shape> MakeHandheld(Random& random);

/// The shape of `kind` with the parameters drawn from the shape stream of `seed`.
std::unique_ptr<const Shape> MakeShape(MotionKind kind, uint64_t seed);

}  // namespace cheval::sim::internal

// The quadrotor model's dynamics (estim::QuadrotorModel, docs/estimator.md "The quadrotor") against
// physics that does not share its code: conservation laws of the torque-free rigid body, a closed
// form, Euler's equations written out here, and the translational acceleration by hand. The
// simulator integrates the model's own Dynamics, so these tests are what catches a wrong sign in it
// (the gyroscopic term ω × Jω, the frame of the thrust).
#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <numbers>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "cheval/estim/models.h"

namespace cheval {
namespace {

// A body with three distinct principal moments (J_y the intermediate one), so ω × Jω is not zero for
// a general ω. 0.003 + 0.005 >= 0.007: a physical body (triangle inequality).
estim::QuadrotorParameters Parameters() {
  estim::QuadrotorParameters p;
  p.mass_kg = 1.0;
  p.inertia_kgm2 = Eigen::Vector3d(0.003, 0.005, 0.007);
  p.arm_m = 0.08;
  p.thrust_coefficient = 1.91e-6;
  p.moment_coefficient = 2.6e-7;
  p.motor_time_constant_s = 0.02;
  p.max_rotor_speed_radps = 2200;
  p.drag_coefficient = 0.1;
  return p;
}

// The rotational state: body rate ω (rad/s) and R_world_body.
struct Rotation {
  Eigen::Vector3d w;
  Eigen::Matrix3d R;
};
using RotationRate = std::function<Rotation(double t, const Rotation& s)>;  // (ω', R')

Eigen::Matrix3d Hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(),  //
      w.z(), 0, -w.x(),   //
      -w.y(), w.x(), 0;
  return m;
}

Rotation Add(const Rotation& s, const Rotation& d, double h) { return {s.w + h * d.w, s.R + h * d.R}; }

// Classical RK4 on (ω, R) with R as a plain 3x3 matrix (no re-orthonormalisation: its drift off
// SO(3) is part of the integrator's O(h⁴) error, which the tolerances below account for).
Rotation Integrate(const RotationRate& rate, Rotation s, double duration, double h) {
  const int steps = static_cast<int>(std::lround(duration / h));
  for (int i = 0; i < steps; ++i) {
    const double t = i * h;
    const Rotation k1 = rate(t, s), k2 = rate(t + h / 2, Add(s, k1, h / 2)), k3 = rate(t + h / 2, Add(s, k2, h / 2)),
                   k4 = rate(t + h, Add(s, k3, h));
    s = {s.w + h / 6 * (k1.w + 2 * k2.w + 2 * k3.w + k4.w), s.R + h / 6 * (k1.R + 2 * k2.R + 2 * k3.R + k4.R)};
  }
  return s;
}

// The model's rotational part: ω' from Dynamics, R' = R [ω]× with the ω Dynamics returns. Position
// and velocity are zero (they do not enter the rotation).
RotationRate ModelRate(const estim::QuadrotorModel& model, std::function<Eigen::Vector4d(double)> rotor) {
  return [&model, rotor](double t, const Rotation& s) {
    const double x[9] = {0, 0, 0, 0, 0, 0, s.w.x(), s.w.y(), s.w.z()};
    const Eigen::Vector4d u = rotor(t);
    double x_dot[9], omega[3];
    model.Dynamics(x, s.R, u.data(), x_dot, omega);
    return Rotation{Eigen::Vector3d(x_dot[6], x_dot[7], x_dot[8]), s.R * Hat(Eigen::Vector3d(omega[0], omega[1], omega[2]))};
  };
}

// Equal rotor speeds: equal thrusts at the four symmetric arms and equal reaction moments of the
// two spin directions cancel, so the body torque is zero (the thrust acts on the translation only).
Eigen::Vector4d Hover(const estim::QuadrotorParameters& p) { return Eigen::Vector4d::Constant(p.HoverRotorSpeed()); }

// Torque-free rotation near the intermediate axis (the body tumbles: ω_y reverses within the 6 s,
// the Dzhanibekov effect, so ω × Jω is large and changes all the time). Physics: d(R J ω)/dt =
// R (ω × Jω + J ω') = R τ = 0, and d(½ ωᵀJω)/dt = ωᵀτ = 0. RK4 at h = 1 ms with |ω| h = 6e-3 drifts
// by at most ~T/h · (|ω|h)⁵ ≈ 5e-8 of |L| (measured: 3e-12 for L, 2.5e-13 for E, 7e-12 off SO(3));
// bounds 1e-9. A flipped gyroscopic term (J ω' = τ + ω × Jω) makes d(RJω)/dt = 2 R (ω × Jω): L
// changes by O(|L|). The energy — and |Jω| — stay conserved with either sign (ωᵀ(ω × Jω) = 0): only
// the world-frame momentum, which couples ω' to R, sees the sign.
TEST(RigidBodyPhysics, TorqueFreeRotationConservesMomentumAndEnergy) {
  const estim::QuadrotorModel model{Parameters()};
  const Eigen::Vector3d J = model.parameters.inertia_kgm2;
  const Eigen::Vector4d hover = Hover(model.parameters);
  ASSERT_LT(model.Torque(hover.data()).norm(), 1e-15);
  const Rotation start{Eigen::Vector3d(0.2, 6.0, 0.3), Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix()};
  const Eigen::Vector3d L0 = start.R * J.cwiseProduct(start.w);
  const double E0 = 0.5 * start.w.dot(J.cwiseProduct(start.w));
  const RotationRate rate = ModelRate(model, [&](double) { return hover; });
  Rotation s = start;
  double min_wy = s.w.y();
  for (int second = 1; second <= 6; ++second) {
    s = Integrate(rate, s, 1.0, 1e-3);
    min_wy = std::min(min_wy, s.w.y());
    const Eigen::Vector3d L = s.R * J.cwiseProduct(s.w);
    const double E = 0.5 * s.w.dot(J.cwiseProduct(s.w));
    EXPECT_LT((L - L0).norm(), 1e-9 * L0.norm()) << "t = " << second << " s: L = " << L.transpose();
    EXPECT_NEAR(E, E0, 1e-9 * E0) << "t = " << second << " s";
  }
  EXPECT_LT(min_wy, 0.0) << "the body did not tumble: the test would not exercise ω × Jω";
  // The rotation stayed a rotation (the integrator's own check).
  EXPECT_LT((s.R.transpose() * s.R - Eigen::Matrix3d::Identity()).norm(), 1e-9);
}

// An axisymmetric body (J = diag(I, I, I₃)) without torque: ω_z is constant and (ω_x, ω_y) turns at
// λ = (I₃ − I) ω_z / I in the body frame (Euler's equations; Landau & Lifshitz, Mechanics, §33):
// ω_x + i ω_y = (ω_x + i ω_y)(0) e^{iλt}. The sign of λ is the sign of the gyroscopic term. RK4's phase
// error over T is ~T λ (λh)⁴/120 ≈ 2e-12 rad here (λ = 2.4 rad/s, h = 1 ms, T = 2.5 s; measured 2e-12
// rad/s); bound 1e-9 rad/s.
TEST(RigidBodyPhysics, AxisymmetricBodyRateTurnsAtTheClosedFormRate) {
  estim::QuadrotorParameters p = Parameters();
  p.inertia_kgm2 = Eigen::Vector3d(0.005, 0.005, 0.008);
  const estim::QuadrotorModel model{p};
  const Eigen::Vector4d hover = Hover(p);
  const double I = 0.005, I3 = 0.008, wz = 4.0, lambda = (I3 - I) * wz / I;
  const std::complex<double> transverse0(1.5, -0.5);
  Rotation s{Eigen::Vector3d(transverse0.real(), transverse0.imag(), wz), Eigen::Matrix3d::Identity()};
  const RotationRate rate = ModelRate(model, [&](double) { return hover; });
  for (int k = 1; k <= 5; ++k) {
    s = Integrate(rate, s, 0.5, 1e-3);
    const std::complex<double> expected = transverse0 * std::exp(std::complex<double>(0, lambda * 0.5 * k));
    EXPECT_NEAR(s.w.x(), expected.real(), 1e-9) << "t = " << 0.5 * k;
    EXPECT_NEAR(s.w.y(), expected.imag(), 1e-9) << "t = " << 0.5 * k;
    EXPECT_NEAR(s.w.z(), wz, 1e-12);
  }
}

// Euler's equations written out here with nothing of the model: J ω' = τ − ω × Jω with J a full
// matrix, Ṙ = R [ω]×, and τ from the motor positions r_i and spins s_i of docs/estimator.md:
// τ = Σ r_i × (0, 0, k_F Ω_i²) + Σ s_i k_M Ω_i² e_z. Rotor speeds vary (all three torques change sign)
// and ω starts off every axis. Both sides use the same RK4 and step, so a correct model agrees to
// rounding (measured 2e-14 rad/s over 3 s, while |ω − ω(0)| reaches 17 rad/s); bound 1e-10.
TEST(RigidBodyPhysics, MatchesEulersEquationsUnderTorque) {
  const estim::QuadrotorParameters p = Parameters();
  const estim::QuadrotorModel model{p};
  const double a = p.arm_m, hover = p.HoverRotorSpeed();
  const Eigen::Vector3d r[4] = {{a, a, 0}, {-a, a, 0}, {-a, -a, 0}, {a, -a, 0}};
  const double spin[4] = {-1, 1, -1, 1};
  const auto rotor = [hover](double t) {
    Eigen::Vector4d u;
    for (int i = 0; i < 4; ++i) u[i] = hover * (1 + 0.04 * std::sin((1.3 + 0.7 * i) * t + 0.9 * i));
    return u;
  };
  const Eigen::Matrix3d J = p.inertia_kgm2.asDiagonal();
  const RotationRate euler = [&](double t, const Rotation& s) {
    const Eigen::Vector4d u = rotor(t);
    Eigen::Vector3d tau = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      const double f = p.thrust_coefficient * u[i] * u[i];
      tau += r[i].cross(Eigen::Vector3d(0, 0, f)) + spin[i] * p.moment_coefficient * u[i] * u[i] * Eigen::Vector3d::UnitZ();
    }
    return Rotation{J.inverse() * (tau - s.w.cross(J * s.w)), s.R * Hat(s.w)};
  };
  const Rotation start{Eigen::Vector3d(1.0, -2.0, 0.5), Eigen::Matrix3d::Identity()};
  Rotation mine = start, theirs = start;
  double turned = 0;  // the largest body rate reached: the torques did act
  for (int k = 1; k <= 6; ++k) {
    mine = Integrate(euler, mine, 0.5, 1e-3);
    theirs = Integrate(ModelRate(model, rotor), theirs, 0.5, 1e-3);
    turned = std::max(turned, (mine.w - start.w).norm());
    EXPECT_LT((theirs.w - mine.w).norm(), 1e-10) << "t = " << 0.5 * k << ": model " << theirs.w.transpose()
                                                 << ", Euler " << mine.w.transpose();
    EXPECT_LT((theirs.R - mine.R).norm(), 1e-10) << "t = " << 0.5 * k;
  }
  EXPECT_GT(turned, 1.0);
}

// The translation by hand: v' = (k_F ΣΩ²/m) R e_z − (c/m)|v| v + (0, 0, −g), thrust along the body z
// axis and expressed in the world frame. m = 0.5 kg, k_F = 1e-6, Ω = (900, 1000, 1100, 1000) rad/s:
// ΣΩ² = 4.02e6, thrust 4.02 N, 8.04 m/s². R = 30° about world x: R e_z = (0, −1/2, √3/2). c = 0.1,
// v = (3, 0, 4) m/s, |v| = 5: drag −(0.1/0.5)·5·v = (−3, 0, −4) m/s². So v' = (−3, −4.02,
// 8.04·√3/2 − 9.81 − 4) and p' = v. A yaw about the body z axis must not change it. Exact up to
// rounding (1e-12).
TEST(RigidBodyPhysics, ThrustAlongBodyZPlusGravityAndDragInTheWorldFrame) {
  estim::QuadrotorParameters p = Parameters();
  p.mass_kg = 0.5;
  p.thrust_coefficient = 1e-6;
  p.drag_coefficient = 0.1;
  p.gravity_mps2 = 9.81;
  const estim::QuadrotorModel model{p};
  const double x[9] = {1, 2, 3, 3, 0, 4, 0.3, -0.2, 0.1};
  const double u[4] = {900, 1000, 1100, 1000};
  const Eigen::Vector3d expected(-3.0, -4.02, 8.04 * std::sqrt(3.0) / 2 - 9.81 - 4.0);
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(std::numbers::pi / 6, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (const double yaw : {0.0, 0.7, -2.0}) {
    const Eigen::Matrix3d R = roll * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    double x_dot[9], omega[3];
    model.Dynamics(x, R, u, x_dot, omega);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(x_dot[i], x[3 + i], 1e-15) << "p' = v, axis " << i;
      EXPECT_NEAR(x_dot[3 + i], expected[i], 1e-12) << "v', axis " << i << ", yaw " << yaw;
      EXPECT_EQ(omega[i], x[6 + i]) << "R' = R [ω]× with the state's ω";
    }
  }
}

}  // namespace
}  // namespace cheval

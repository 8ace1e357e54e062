#pragma once
/// \file
/// Dynamics models for the pseudo-spectral estimator (docs/estimator.md). A model is any type with
///
/// | member | meaning |
/// |---|---|
/// | `static constexpr int kVectorDim` | dimension of the vector part of the state (everything but a rotation) |
/// | `static constexpr int kBlockSize` | the vector part is split into Ceres parameter blocks of this size (divides kVectorDim) |
/// | `static constexpr bool kHasRotation` | whether the state also holds a rotation R_world_body ∈ SO(3) |
/// | `static constexpr int kControlDim` | dimension of the control u |
/// | `template <class T> void Dynamics(const T* x, const Eigen::Matrix<T,3,3>& R, const T* u, T* x_dot, T* omega) const` | x' = f(x, u) for the vector part, and the body angular velocity ω (R' = R [ω]×) when kHasRotation (ignore R and omega otherwise) |
///
/// Dynamics is templated on the scalar so ceres::Jet gives its Jacobians (autodiff). The tangent of
/// the state is (vector part, rotation as a right perturbation R Exp(δ)), dimension kVectorDim + 3.

#include <cmath>

#include <Eigen/Core>

namespace cheval::estim {

/// Physical parameters of an X-configuration quadrotor (docs/estimator.md, "The quadrotor"). SI units.
/// Motors (FlightGoggles convention, numbered counter-clockwise seen from above, 0 = front-left):
/// 0 at (+a, +a) spin −1; 1 at (−a, +a) spin +1; 2 at (−a, −a) spin −1; 3 at (+a, −a) spin +1 (body
/// x forward, y left, z up).
struct QuadrotorParameters {
  double mass_kg = 0;                                       ///< m > 0
  Eigen::Vector3d inertia_kgm2 = Eigen::Vector3d::Zero();   ///< diag(J), each > 0 (principal axes = body axes)
  double arm_m = 0;                                         ///< a: motor offset along body x and y, > 0
  double thrust_coefficient = 0;                            ///< k_F: f_i = k_F Ω_i², N/(rad/s)², > 0
  double moment_coefficient = 0;                            ///< k_M: yaw torque k_M Ω_i², N m/(rad/s)², >= 0
  double motor_time_constant_s = 0;                         ///< first-order motor lag (simulator only), > 0
  double max_rotor_speed_radps = 0;                         ///< rotor speed limit, > 0
  double drag_coefficient = 0;                              ///< c: drag force −c |v| v (world frame), >= 0
  double gravity_mps2 = 9.81;                               ///< |g|, g = (0, 0, −|g|)

  /// The rotor speed at which the four rotors carry the weight: sqrt(m |g| / (4 k_F)), rad/s.
  double HoverRotorSpeed() const { return std::sqrt(mass_kg * gravity_mps2 / (4.0 * thrust_coefficient)); }
};

/// The quadrotor of docs/estimator.md as an estimator model. Vector state (9): p (world, m), v (world,
/// m/s), ω (body, rad/s) in blocks of 3; rotation R_world_body; control (4): rotor speeds Ω_i (rad/s).
/// p' = v; R' = R[ω]×; v' = g + (k_F Σ Ω_i² / m) R e3 − (c/m)|v| v; ω' = J⁻¹(τ − ω × Jω), τ as in
/// Torque below (rotor speeds are taken as the true speeds: the motor lag is not part of f).
struct QuadrotorModel {
  static constexpr int kVectorDim = 9;
  static constexpr int kBlockSize = 3;
  static constexpr bool kHasRotation = true;
  static constexpr int kControlDim = 4;

  QuadrotorParameters parameters;

  /// Thrust f_i = k_F Ω_i² of each rotor (N).
  template <typename T>
  void RotorForces(const T* u, T* f) const {
    for (int i = 0; i < 4; ++i) f[i] = T(parameters.thrust_coefficient) * u[i] * u[i];
  }

  /// Body torque τ (N m) of rotor speeds u.
  template <typename T>
  Eigen::Matrix<T, 3, 1> Torque(const T* u) const {
    T f[4];
    RotorForces(u, f);
    const T a(parameters.arm_m), km(parameters.moment_coefficient);
    return Eigen::Matrix<T, 3, 1>(a * (f[0] + f[1] - f[2] - f[3]), a * (-f[0] + f[1] + f[2] - f[3]),
                                  km * (-u[0] * u[0] + u[1] * u[1] - u[2] * u[2] + u[3] * u[3]));
  }

  template <typename T>
  void Dynamics(const T* x, const Eigen::Matrix<T, 3, 3>& R, const T* u, T* x_dot, T* omega) const {
    using std::sqrt;
    const QuadrotorParameters& q = parameters;
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> v(x + 3), w(x + 6);
    T f[4];
    RotorForces(u, f);
    const T thrust = f[0] + f[1] + f[2] + f[3];
    const T speed_squared = v.squaredNorm();
    // |v| v has derivative 0 at v = 0, but sqrt's Jet derivative there is not finite: branch.
    const T speed = speed_squared > T(0) ? sqrt(speed_squared) : T(0);
    const Eigen::Matrix<T, 3, 1> accel = R.col(2) * (thrust / T(q.mass_kg)) -
                                         v * (T(q.drag_coefficient) * speed / T(q.mass_kg)) +
                                         Eigen::Matrix<T, 3, 1>(T(0), T(0), T(-q.gravity_mps2));
    const Eigen::Matrix<T, 3, 1> J = q.inertia_kgm2.cast<T>();
    const Eigen::Matrix<T, 3, 1> Jw = J.cwiseProduct(w);
    const Eigen::Matrix<T, 3, 1> w_dot = (Torque(u) - w.cross(Jw)).cwiseQuotient(J);
    for (int i = 0; i < 3; ++i) {
      x_dot[i] = v[i];
      x_dot[3 + i] = accel[i];
      x_dot[6 + i] = w_dot[i];
      omega[i] = w[i];
    }
  }
};

}  // namespace cheval::estim

#pragma once
/// \file
/// The rigid-body quadrotor of a real vehicle with measured rotor speeds (docs/estimator_real_data.md,
/// "The rotor model"), with the parameters that identification estimates (θ) kept apart from the ones
/// it takes as known (mass, arm), so that the same dynamics serve `estimate rotors` (θ known) and
/// `identify rotors` (θ a Ceres parameter block, internal/parametric_collocation_cost.h).
///
/// X layout, Crazyflie numbering (SOURCE.md of the data): motor i at body (x_i, y_i) = l·(+1, −1),
/// (−1, −1), (−1, +1), (+1, +1) for m1..m4 (body x forward, y left, z up), yaw sign s = (+1, −1, +1, −1):
///
///   f_i = k_i Ω_i²,  T = Σ f_i,  τ = (l(−f1 − f2 + f3 + f4), l(−f1 + f2 + f3 − f4), k_M Σ s_i Ω_i²) + τ0
///        + (Σ Ω_i) (b_x v_y, −b_y v_x, 0)   (v_x, v_y: body-frame velocity)
///        + c_r (ω_y Y, −ω_x Y, Y')   (Y = Σ s_i Ω_i: the rotors' reaction, below),
///   p' = v,  R' = R[ω]×,  v' = g + R (T/m e3 − (Σ Ω_i) diag(d_xy, d_xy, d_z) Rᵀ v),
///   ω' = J⁻¹(τ − ω × Jω),  g = (0, 0, −|g|).
///
/// With k_i = k_F these are exactly the published mixer (T = Kt Σω², τx = Kt l((ω3²+ω4²) − (ω1²+ω2²)),
/// τy = Kt l((ω2²+ω3²) − (ω1²+ω4²)), τz = Kc((ω1²+ω3²) − (ω2²+ω4²))). The extra terms are physics the
/// published model leaves out: per-motor thrust coefficients (propellers and motors differ), a constant
/// torque τ0 (centre of mass off the rotors' centre), rotor drag — the specific force of blade
/// flapping and induced drag, proportional to Σ Ω_i and the body-frame velocity (Mahony, Kumar &
/// Corke 2012, "Multirotor aerial vehicles", §IV) — and the rotor moment of the same flapping, which
/// tilts the rotor discs away from the horizontal airspeed (nose up in forward flight). On the
/// Crazyflie flights the rotor moment explains 80–90 % of the variance of the roll and pitch
/// rotor-speed differences, the angular acceleration a few % (docs/estimator_real_data.md). The
/// rotors' own angular momentum h = −c_r Y e3 (c_r = −I_r times the spin sign of the motors with s = +1)
/// gives the body the reaction −h' − ω × h: the torque of spinning the rotors up and down, by which a
/// quadrotor yaws as much as by the rotors' drag torque k_M Ω² (on the Crazyflie flights the yaw
/// acceleration's variance explained by the drag torque alone is 13–63 %, with the reaction 62–83 %).
///
/// θ is held in units where the published vehicle is θ = (1, 1, 1, 1, 1, 1, 1, 1, 0, ..., 0)
/// (then zeros), which keeps the solver's steps well scaled (the raw values span 1e-12 .. 1e-5).

#include <array>
#include <cmath>

#include <Eigen/Core>

namespace cheval::estim {

/// Index of each identified parameter in θ.
enum RotorTheta : int {
  kThetaThrust0 = 0,  ///< k_i / k_F published, i = 0..3 (m1..m4)
  kThetaInertiaX = 4,  ///< J_x / J_x published (and Y, Z next)
  kThetaMoment = 7,    ///< k_M / Kc published (sign included: the data decide the spin directions)
  kThetaTorqueX = 8,   ///< τ0 in units of kRotorTorqueUnit (and Y, Z next)
  kThetaDragXY = 11,   ///< d_xy in units of kRotorDragUnit
  kThetaDragZ = 12,    ///< d_z in units of kRotorDragUnit
  kThetaFlapX = 13,    ///< rotor moment b_x in units of kRotorFlapUnit (and Y next)
  kThetaRotorInertia = 15,  ///< c_r in units of kRotorInertiaUnit (sign: the spin directions')
  kRotorThetaSize = 16
};

/// The unit of τ0 in θ, N m (about 1 % of a hover rotor's roll torque on a Crazyflie).
inline constexpr double kRotorTorqueUnit = 1e-5;
/// The unit of the rotor-drag coefficients in θ, (m/s²) per (rad/s · m/s).
inline constexpr double kRotorDragUnit = 1e-5;
/// The unit of the rotor-moment coefficients in θ, N m per (rad/s · m/s).
inline constexpr double kRotorFlapUnit = 1e-8;

/// The unit of the rotor-inertia coefficient c_r in θ, kg m² (a few % of a nano-quadrotor's yaw inertia).
inline constexpr double kRotorInertiaUnit = 1e-9;

using RotorThetaVector = Eigen::Matrix<double, kRotorThetaSize, 1>;

/// The published (nominal) vehicle: the known constants and the reference values θ is relative to.
struct RotorNominal {
  double mass_kg = 0;                                      ///< m > 0 (known, not identified)
  double arm_m = 0;                                        ///< l: per-axis lever, > 0 (known)
  double thrust_coefficient = 0;                           ///< k_F published, N/(rad/s)², > 0
  double moment_coefficient = 0;                           ///< Kc published, N m/(rad/s)², > 0
  Eigen::Vector3d inertia_kgm2 = Eigen::Vector3d::Zero();  ///< J published, each > 0
  double gravity_mps2 = 9.81;                              ///< |g|

  /// θ of the published vehicle itself.
  static RotorThetaVector PublishedTheta() {
    RotorThetaVector theta = RotorThetaVector::Zero();
    theta.head<8>().setOnes();
    return theta;
  }
};

/// p', v', ω' of the model above at state x = (p, v, ω), rotation R, rotor speeds u and their
/// derivatives u_dot (m1..m4, rad/s and rad/s²) and parameters θ (any scalar types, for ceres::Jet).
template <typename T, typename P>
void RotorDynamics(const RotorNominal& n, const T* x, const Eigen::Matrix<T, 3, 3>& R, const T* u, const T* u_dot,
                   const P* theta, T* x_dot) {
  using Vec = Eigen::Matrix<T, 3, 1>;
  const Vec v(x[3], x[4], x[5]), w(x[6], x[7], x[8]);
  T f[4], sum_speed = T(0);
  for (int i = 0; i < 4; ++i) {
    f[i] = T(n.thrust_coefficient) * theta[kThetaThrust0 + i] * u[i] * u[i];
    sum_speed += u[i];
  }
  const T thrust = f[0] + f[1] + f[2] + f[3];
  const Vec body_v = R.transpose() * v;
  const T dxy = theta[kThetaDragXY] * T(kRotorDragUnit), dz = theta[kThetaDragZ] * T(kRotorDragUnit);
  const Vec body_force(-sum_speed * dxy * body_v.x(), -sum_speed * dxy * body_v.y(),
                       thrust / T(n.mass_kg) - sum_speed * dz * body_v.z());
  const Vec accel = R * body_force + Vec(T(0), T(0), T(-n.gravity_mps2));
  const T l(n.arm_m);
  const T yaw = u[0] * u[0] - u[1] * u[1] + u[2] * u[2] - u[3] * u[3];
  const T flap = sum_speed * T(kRotorFlapUnit);
  const T c_r = theta[kThetaRotorInertia] * T(kRotorInertiaUnit);
  const T spin = u[0] - u[1] + u[2] - u[3], spin_dot = u_dot[0] - u_dot[1] + u_dot[2] - u_dot[3];
  const Vec tau(l * (-f[0] - f[1] + f[2] + f[3]) + theta[kThetaTorqueX] * T(kRotorTorqueUnit) +
                    flap * theta[kThetaFlapX] * body_v.y() + c_r * spin * w.y(),
                l * (-f[0] + f[1] + f[2] - f[3]) + theta[kThetaTorqueX + 1] * T(kRotorTorqueUnit) -
                    flap * theta[kThetaFlapX + 1] * body_v.x() - c_r * spin * w.x(),
                T(n.moment_coefficient) * theta[kThetaMoment] * yaw + theta[kThetaTorqueX + 2] * T(kRotorTorqueUnit) +
                    c_r * spin_dot);
  const Vec J(T(n.inertia_kgm2.x()) * theta[kThetaInertiaX], T(n.inertia_kgm2.y()) * theta[kThetaInertiaX + 1],
              T(n.inertia_kgm2.z()) * theta[kThetaInertiaX + 2]);
  const Vec w_dot = (tau - w.cross(J.cwiseProduct(w))).cwiseQuotient(J);
  for (int i = 0; i < 3; ++i) {
    x_dot[i] = v[i];
    x_dot[3 + i] = accel[i];
    x_dot[6 + i] = w_dot[i];
  }
}

/// The model with θ known, for PseudoSpectralProblem (models.h): vector state p, v, ω (blocks of 3),
/// rotation R_world_body, control the four rotor speeds m1..m4 (rad/s). Its Dynamics has no rotor
/// accelerations: it serves the kinematic parts (p' = v, R' = R[ω]×) only; v' and ω' are
/// ParametricCollocationCost's, which differentiates the rotor polynomials.
struct RotorModel {
  static constexpr int kVectorDim = 9;
  static constexpr int kBlockSize = 3;
  static constexpr bool kHasRotation = true;
  static constexpr int kControlDim = 4;

  RotorNominal nominal;
  RotorThetaVector theta = RotorNominal::PublishedTheta();

  template <typename T>
  void Dynamics(const T* x, const Eigen::Matrix<T, 3, 3>& R, const T* u, T* x_dot, T* omega) const {
    const T no_rates[4] = {T(0), T(0), T(0), T(0)};
    RotorDynamics(nominal, x, R, u, no_rates, theta.data(), x_dot);
    for (int i = 0; i < 3; ++i) omega[i] = x[6 + i];
  }
};

}  // namespace cheval::estim

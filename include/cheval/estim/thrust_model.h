#pragma once
/// \file
/// Translational quadrotor dynamics with a known attitude, for real data where mass, inertia and
/// rotor layout are unknown but a mass-normalised thrust coefficient is (docs/estimator_real_data.md).
/// A model for PseudoSpectralProblem (models.h): vector state p, v (world), no SO(3) state; the
/// control is the collective rotor speed Ω_c plus the thrust frame's attitude R_world_thrust, which is
/// a known, exogenous input (the measured attitude) that the estimator holds constant (SubsetManifold).

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cheval::estim {

/// Coefficients of the translational model, SI units, rotor speeds in rad/s.
///
/// v' = g + 4 k Ω_c² R e3 − 4 Ω_c R diag(D) Rᵀ v − c |v| v,   g = (0, 0, −|g|),
///
/// with Ω_c = sqrt(¼ Σ Ω_i²) the collective rotor speed (the speed that, on all four rotors, gives the
/// same thrust), R = R_world_thrust. This is DIDO's model (DIDO_SupMat eq. 3–7, Translation_stage.py:
/// a_body = kf Σu_i² e3 − Σu_i diag(D) v_body) with Σu_i ≈ 4 Ω_c (exact for equal rotor speeds; with
/// the ~2 % rms rotor spread of the DIDO flights they differ by ½(σ/μ)² ≈ 0.02 %, of a drag term below
/// ~0.7 m/s²), plus the world-frame quadratic drag of QuadrotorModel (models.h) so that the
/// simulator's vehicle is also described exactly.
struct ThrustParameters {
  double thrust_per_mass = 0;                             ///< k = k_F/m: (m/s²)/(rad/s)² per rotor, > 0
  Eigen::Vector3d rotor_drag = Eigen::Vector3d::Zero();   ///< D: body-frame drag diag(D) Σ Ω_i v_body, (m/s²) per (rad/s · m/s)
  double quadratic_drag_per_mass = 0;                     ///< c = drag/m: world drag −c|v|v, 1/m, >= 0
  double gravity_mps2 = 9.81;                             ///< |g| > 0

  /// Ω_c at which the thrust carries the weight: sqrt(|g| / (4 k)), rad/s.
  double HoverRotorSpeed() const { return std::sqrt(gravity_mps2 / (4.0 * thrust_per_mass)); }
};

/// The model. Vector state (6): p (world, m), v (world, m/s), blocks of 3. Control (5): Ω_c (rad/s),
/// then R_world_thrust as a unit quaternion (x, y, z, w), which the caller holds constant.
struct ThrustModel {
  static constexpr int kVectorDim = 6;
  static constexpr int kBlockSize = 3;
  static constexpr bool kHasRotation = false;
  static constexpr int kControlDim = 5;

  ThrustParameters parameters;

  /// The world acceleration v' for velocity v, collective Ω_c and thrust attitude R.
  template <typename T>
  Eigen::Matrix<T, 3, 1> Acceleration(const Eigen::Matrix<T, 3, 1>& v, const T& collective,
                                      const Eigen::Matrix<T, 3, 3>& R) const {
    using std::sqrt;
    const ThrustParameters& k = parameters;
    const T speed_squared = v.squaredNorm();
    // |v| v has derivative 0 at v = 0, but sqrt's Jet derivative there is not finite: branch.
    const T speed = speed_squared > T(0) ? sqrt(speed_squared) : T(0);
    const Eigen::Matrix<T, 3, 1> body_v = R.transpose() * v;
    const Eigen::Matrix<T, 3, 1> body_drag = k.rotor_drag.cast<T>().cwiseProduct(body_v) * (T(4) * collective);
    return R.col(2) * (T(4 * k.thrust_per_mass) * collective * collective) - R * body_drag -
           v * (T(k.quadratic_drag_per_mass) * speed) + Eigen::Matrix<T, 3, 1>(T(0), T(0), T(-k.gravity_mps2));
  }

  template <typename T>
  void Dynamics(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, const T* u, T* x_dot, T* /*omega*/) const {
    const Eigen::Matrix<T, 3, 1> v(x[3], x[4], x[5]);
    const Eigen::Matrix<T, 3, 3> R = Eigen::Quaternion<T>(u[4], u[1], u[2], u[3]).normalized().toRotationMatrix();
    const Eigen::Matrix<T, 3, 1> a = Acceleration(v, u[0], R);
    for (int i = 0; i < 3; ++i) {
      x_dot[i] = v[i];
      x_dot[3 + i] = a[i];
    }
  }
};

}  // namespace cheval::estim

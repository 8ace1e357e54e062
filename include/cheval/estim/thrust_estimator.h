#pragma once
/// \file
/// The collective rotor speed of a quadrotor from positions (and optionally an accelerometer), its
/// measured attitude and the translational dynamics of thrust_model.h, on the pseudo-spectral problem
/// (problem.h). Written for the real DIDO flights (docs/estimator_real_data.md has the data, the
/// formats and the results), also fed from the simulator (sim/quadrotor.h) for tests.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/estim/thrust_model.h"

namespace cheval::estim {

/// One sample of a flight. The measured point is the IMU (DIDO) or the body origin (simulator).
struct ThrustSample {
  double t = 0;                                           ///< s
  Eigen::Vector3d p = Eigen::Vector3d::Zero();            ///< position of the measured point, world, m
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  ///< R_world_imu
  Eigen::Vector3d v = Eigen::Vector3d::Zero();            ///< velocity of the measured point, world, m/s (truth)
  Eigen::Vector3d w = Eigen::Vector3d::Zero();            ///< body rate, IMU frame, rad/s
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();        ///< angular acceleration, IMU frame, rad/s²
  Eigen::Vector3d a = Eigen::Vector3d::Zero();            ///< acceleration of the measured point, world, m/s² (truth)
  Eigen::Vector3d accelerometer = Eigen::Vector3d::Zero();///< specific force, IMU frame, m/s²
  Eigen::Vector4d rotor = Eigen::Vector4d::Zero();        ///< measured rotor speeds, rad/s
};

/// A flight and the vehicle's identified translational parameters.
struct ThrustFlight {
  std::string name;
  std::vector<ThrustSample> samples;  ///< strictly increasing t
  ThrustParameters parameters;
  /// Extrinsics of the thrust ("rigid body") frame: its origin at the IMU + R_world_imu t_imu_thrust,
  /// its axes R_world_thrust = R_world_imu R_imu_thrust (DIDO's t_IB and pitch/roll extrinsic).
  Eigen::Vector3d t_imu_thrust = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_imu_thrust = Eigen::Matrix3d::Identity();
};

/// Reads a DIDO sequence CSV (header t_s,p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x,v_y,v_z,gt_gyr_x..z,
/// gt_acc_x..z,gt_alpha_x..z,imu_acc_x..z,imu_gyr_x..z,rpm_1..rpm_4; docs/estimator_real_data.md). Rotor speeds are
/// converted from rpm to rad/s. Throws InputError (`path:line:column: error: ...`) for a missing file,
/// a header that differs, a wrong field count, a non-finite number, a zero quaternion, a negative
/// rotor speed or time stamps that do not increase.
std::vector<ThrustSample> ReadDidoCsv(const std::string& path);

/// DIDO's identified parameters of one sequence (`*.dynamic_params.csv`: kf_massnorm, D_x, D_y, D_z,
/// t_imu_to_body_x..z, pitch_ex_deg, roll_ex_deg; docs/estimator_real_data.md) converted to SI:
/// kf is (m/s²)/(1e4 rpm)² per Σu_i², so k = kf (30 / (π 1e4))² (m/s²)/(rad/s)²; D is per Σu_i in
/// 1e4 rpm, so D_SI = D · 30 / (π 1e4); |g| = 9.8 (DIDO's gravity); R_imu_thrust =
/// (R_y(pitch) R_x(roll))ᵀ (scipy from_euler("xyz", [roll, pitch, 0]).T, "rigid2imu").
/// InputError as ReadDidoCsv; kf must be > 0.
struct DidoParameters {
  ThrustParameters parameters;
  Eigen::Vector3d t_imu_thrust = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_imu_thrust = Eigen::Matrix3d::Identity();
};
DidoParameters ReadDidoParameters(const std::string& path);

/// Reads a DIDO sequence and its parameters (`params_path` empty: the CSV's name with .csv replaced
/// by .dynamic_params.csv).
ThrustFlight ReadDidoFlight(const std::string& csv_path, std::string params_path = "");

/// Options, one default set for the simulator and the real flights (docs/estimator_real_data.md).
struct ThrustEstimateOptions {
  int degree = 10;                 ///< polynomial degree per segment, in [2, 64]
  double segment_s = 1.0;          ///< segment length, s > 0
  double position_rate_hz = 30.0;  ///< rate at which the positions are used (a VO-like rate), > 0
  double position_sigma_m = 0.005; ///< σ of a position measurement, m > 0
  double position_noise_m = 0.0;   ///< white noise added to the used positions (seeded), m >= 0
  uint64_t seed = 1;               ///< of that noise
  bool use_imu = false;            ///< also the accelerometer, at every sample
  double imu_sigma_mps2 = 0.5;     ///< σ of one accelerometer sample per axis, m/s² > 0
  double sigma_position_rate = 1e-3;   ///< collocation σ of p' = v, m/s
  double sigma_acceleration = 0.1;     ///< collocation σ of v' = f, m/s² (covers the model's error)
  double sigma_rotor_rate = 100.0;     ///< Ω_c rate prior (AddControlRatePrior), rad/s² per s^(1/2) (>= 0; 0: not added)
  /// The rotor-speed log is taken to lag the true speeds by this much (s, |d| <= 1):
  /// the measured collective compared at t is the log's (linearly interpolated) value at t + d.
  /// Evaluation only; the estimator never sees the rotor speeds.
  double rotor_delay_s = 0.0;
  int max_iterations = 50;  ///< >= 1
  int threads = 1;          ///< >= 1

  /// Throws OptionError naming the first field out of its range (above).
  void Validate() const;
};

/// Errors of a collective rotor-speed series against the measured one (mean over the flight's
/// samples inside the estimated interval; the measured collective is sqrt(¼ Σ Ω_i²)).
struct CollectiveErrors {
  int samples = 0;
  double mean_abs_rpm = 0;      ///< mean |Ω̂_c − Ω_c|
  double mean_abs_percent = 0;  ///< the same, % of the mean measured Ω_c
  double rmse_rpm = 0;
  double bias_rpm = 0;          ///< mean (Ω̂_c − Ω_c)
};

/// What EstimateThrust returns.
struct ThrustEstimate {
  int states = 0, segments = 0, degree = 0, iterations = 0;
  int position_measurements = 0, imu_measurements = 0;
  double seconds = 0;  ///< wall time of the whole call (building, solving, evaluating)
  bool converged = false;
  std::string solver_report;
  double mean_measured_rpm = 0;    ///< mean measured collective
  CollectiveErrors estimate;       ///< the estimator
  CollectiveErrors flatness;       ///< baseline: Ω_c from finite-differenced used positions (same model)
  CollectiveErrors accelerometer;  ///< baseline: Ω_c from each accelerometer sample alone (same model)
  CollectiveErrors model_floor;    ///< oracle: Ω_c from the true acceleration (the model's own error)
  double position_rmse_m = 0, velocity_rmse_mps = 0;  ///< of the thrust-frame origin vs the truth
  std::vector<double> t;           ///< sample times (s from the first sample) with...
  std::vector<double> estimated_rpm, measured_rpm;  ///< ... Ω̂_c and the measured Ω_c there
};

/// Collective rotor speed sqrt(¼ Σ Ω_i²), same unit as `rotor`.
double CollectiveRotorSpeed(const Eigen::Vector4d& rotor);

/// Ω_c ≥ 0 that explains the world acceleration `a` at world velocity `v` and attitude R_world_thrust
/// by the model's thrust-axis row (thrust_model.h): e3ᵀRᵀ(a − g + c|v|v) = 4kΩ² − 4 D_z (Rᵀv)_z Ω
/// (the larger root; 0 when there is no real non-negative root). What "flatness" gives.
double CollectiveFromAcceleration(const ThrustParameters& parameters, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& v, const Eigen::Matrix3d& R_world_thrust);

/// Estimates the flight over [first, last] sample time. Throws OptionError for bad options,
/// ComputeError with fewer than 3 position measurements.
ThrustEstimate EstimateThrust(const ThrustFlight& flight, const ThrustEstimateOptions& options);

}  // namespace cheval::estim

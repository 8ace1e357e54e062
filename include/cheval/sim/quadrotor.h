#pragma once
/// \file
/// A quadrotor flight simulator for the estimator (docs/estimator.md): the rigid body of
/// estim::QuadrotorModel with first-order motor lag Ω' = (Ω_cmd − Ω)/τ, integrated by RK4 at 1 kHz;
/// a continuous-time geometric controller (Lee, Leok & McClamroch, CDC 2010) tracking one of six
/// reference flights computes Ω_cmd inside every RK4 stage, so rotor speeds are smooth; a forward-
/// looking pinhole camera sees known landmarks on the walls of a 20 m x 20 m x 6 m room with pixel
/// noise at the camera rate; a visual-odometry-like front end gives noisy, drifting initial poses.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cheval/estim/quadrotor_estimator.h"
#include "cheval/estim/vehicle.h"

namespace cheval::sim {

/// Reference flights of increasing complexity (docs/estimator.md has the formulas).
enum class QuadrotorScenario { kHover, kLine, kCircle, kFigureEight, kLissajous, kAggressive };

/// "hover", "line", "circle", "figure8", "lissajous", "aggressive".
std::string_view ToString(QuadrotorScenario scenario);
/// Parses a name as ToString spells it; nullopt if unknown.
std::optional<QuadrotorScenario> QuadrotorScenarioFromString(std::string_view name);
/// Every scenario, in order of complexity.
std::vector<QuadrotorScenario> AllQuadrotorScenarios();

/// What to simulate. Validated by SimulateQuadrotor (UsageError naming the option).
struct QuadrotorSimOptions {
  QuadrotorScenario scenario = QuadrotorScenario::kHover;
  uint64_t seed = 1;                       ///< landmarks, pixel noise and front-end noise
  double duration_s = 10.0;                ///< > 0, <= 3600
  double integration_rate_hz = 1000.0;     ///< RK4 steps per second
  double truth_rate_hz = 100.0;            ///< rate of the ground-truth samples written
  int landmarks = 600;                     ///< landmarks on the walls, floor and ceiling
  int max_features_per_frame = 40;         ///< a front end tracks at most this many
  double vo_position_noise_m = 0.02;       ///< white noise of the front end's positions
  double vo_rotation_noise_rad = 0.005;    ///< white noise of its orientations (right perturbation)
  double vo_position_drift_m_per_sqrt_s = 0.05;     ///< random-walk drift of its positions
  double vo_rotation_drift_rad_per_sqrt_s = 0.01;   ///< random-walk drift of its orientations
};

/// The exact state of the vehicle at one time.
struct QuadrotorTruth {
  double t = 0;                    ///< s
  Eigen::Vector3d p;               ///< position, world, m
  Eigen::Quaterniond q;            ///< R_world_body
  Eigen::Vector3d v;               ///< velocity, world, m/s
  Eigen::Vector3d w;               ///< body rate, rad/s
  Eigen::Vector4d rotor;           ///< rotor speeds Ω_0..3, rad/s
};

/// One pixel measurement of a landmark (index into QuadrotorData::landmarks).
using PixelMeasurement = estim::PixelObservation;
/// A pose of the initial trajectory (front end), at a frame time.
using PoseSample = estim::PoseSample;

/// Errors of an estimate against the ground truth at the truth samples inside the estimated interval.
struct QuadrotorErrors {
  int samples = 0;
  Eigen::Vector4d rotor_error_rpm = Eigen::Vector4d::Zero();      ///< mean |Ω̂_i − Ω_i| per motor, rpm
  Eigen::Vector4d rotor_error_percent = Eigen::Vector4d::Zero();  ///< the same, % of the motor's mean true speed
  double position_rmse_m = 0, rotation_rmse_deg = 0, velocity_rmse_mps = 0;
};

/// Compares an estimate with the truth at the truth samples (the estimate is re-interpolated there:
/// pass the truth times as query times to EstimateQuadrotor). ComputeError when no sample overlaps.
QuadrotorErrors CompareWithTruth(const estim::QuadrotorEstimate& estimate, const std::vector<QuadrotorTruth>& truth);

/// Everything the estimator gets (vehicle, landmarks, measurements, initial poses) and, for
/// evaluation only, the ground truth (empty when a data folder has none).
struct QuadrotorData {
  estim::Vehicle vehicle;
  std::vector<Eigen::Vector3d> landmarks;
  std::vector<PixelMeasurement> pixels;  ///< sorted by time
  std::vector<PoseSample> initial;       ///< one per camera frame
  std::vector<QuadrotorTruth> truth;     ///< at truth_rate_hz
  int saturated_steps = 0;               ///< RK4 steps where a rotor command hit 0 or the limit
};

/// Simulates a flight. Throws UsageError for bad options, ComputeError if the vehicle cannot fly
/// the scenario (a command beyond the rotor limit for more than 1 % of the steps).
QuadrotorData SimulateQuadrotor(const estim::Vehicle& vehicle, const QuadrotorSimOptions& options);

/// Projects world point `x` seen from pose (p, R_world_body): pixel, or nullopt when behind the
/// camera (depth < 0.1 m) or outside the image.
std::optional<Eigen::Vector2d> Project(const estim::PinholeCamera& camera, const Eigen::Vector3d& p,
                                       const Eigen::Matrix3d& R, const Eigen::Vector3d& x);

/// The times an estimate of `data` is reported at: the truth's times when the data has a truth (so
/// CompareWithTruth can use them), else every 10 ms from the first front-end pose to the last.
std::vector<double> ReportTimes(const QuadrotorData& data);

/// The states of an estimate in the layout of QuadrotorTruth (its samples, in time order).
std::vector<QuadrotorTruth> EstimatedStates(const estim::QuadrotorEstimate& estimate);

/// The CSV text of states as truth.csv holds them (docs/estimator.md): header
/// `t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,rotor0,rotor1,rotor2,rotor3`, numbers with 17
/// significant digits. `cheval estimate quadrotor -o FILE` writes an estimate this way.
std::string QuadrotorStatesCsv(const std::vector<QuadrotorTruth>& states);

/// The JSON object of `cheval estimate quadrotor --json` (docs/estimator.md): states, segments,
/// degree, iterations, seconds, converged and, when `errors` is given, rotor_error_rpm,
/// rotor_error_percent (4 numbers each), position_rmse_m, rotation_rmse_deg, velocity_rmse_mps.
/// The Python module returns the same object as a dict.
std::string QuadrotorEstimateJson(const estim::QuadrotorEstimate& estimate, const QuadrotorErrors* errors);

/// Writes a data folder (docs/estimator.md): vehicle.json, landmarks.csv, measurements.csv,
/// initial.csv and truth.csv. Creates the folder. OutputError when a file cannot be written.
void WriteQuadrotorData(const QuadrotorData& data, const std::string& folder);

/// Reads a data folder. truth.csv is optional; every other file is required. InputError naming
/// the missing or malformed file (and line).
QuadrotorData ReadQuadrotorData(const std::string& folder);

}  // namespace cheval::sim

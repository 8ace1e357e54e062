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

#include "cheval/estim/quadrotor_data.h"
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

/// What to simulate. SimulateQuadrotor calls Validate().
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

  /// Throws OptionError naming the first field out of range: duration_s in (0, 3600],
  /// integration_rate_hz in [100, 1e5], truth_rate_hz in (0, integration_rate_hz], landmarks and
  /// max_features_per_frame > 0, the four front-end noise and drift levels finite and >= 0; the truth
  /// samples and the landmarks each within kMaxQuadrotorSimBytes (below).
  void Validate() const;
};

/// The most memory a simulation may take (its data and the text of its data folder), bytes.
inline constexpr double kMaxQuadrotorSimBytes = 2e9;
/// Bytes per item that QuadrotorSimBytes counts (the stored sample plus its CSV row), measured on
/// the shipped vehicle: a truth sample, a landmark, a frame (its initial pose) and a pixel measurement.
inline constexpr double kTruthSampleBytes = 520, kLandmarkBytes = 110, kFrameBytes = 260, kPixelBytes = 130;

/// The memory SimulateQuadrotor would take, bytes: truth samples (duration · truth_rate_hz),
/// landmarks, and per camera frame (duration · camera.rate_hz) its initial pose and up to
/// min(max_features_per_frame, landmarks) pixel measurements, each at the sizes above.
double QuadrotorSimBytes(const estim::Vehicle& vehicle, const QuadrotorSimOptions& options);

/// Simulates a flight: the estimator's input (estim/quadrotor_data.h) with its ground truth at
/// truth_rate_hz. Throws OptionError for bad options (Validate), InputError for a bad vehicle,
/// ComputeError when QuadrotorSimBytes exceeds kMaxQuadrotorSimBytes (naming camera.rate_hz),
/// ComputeError if the vehicle cannot fly the scenario (a command beyond the rotor limit for more
/// than 1 % of the steps).
estim::QuadrotorData SimulateQuadrotor(const estim::Vehicle& vehicle, const QuadrotorSimOptions& options);

/// Projects world point `x` seen from pose (p, R_world_body): pixel, or nullopt when behind the
/// camera (depth < 0.1 m) or outside the image.
std::optional<Eigen::Vector2d> Project(const estim::PinholeCamera& camera, const Eigen::Vector3d& p,
                                       const Eigen::Matrix3d& R, const Eigen::Vector3d& x);

}  // namespace cheval::sim

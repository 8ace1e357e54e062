#pragma once
/// \file
/// All four rotor speeds of a real quadrotor from motion capture, its onboard attitude and body
/// rates and the rigid-body dynamics (rotor_model.h) on the pseudo-spectral problem (problem.h), the
/// identification of the model's parameters from flights with measured rotor speeds, and the flatness
/// baseline they are compared with (docs/estimator_real_data.md, "Rotor speeds of a Crazyflie").

#include <algorithm>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>

#include "cheval/estim/crazyflie_data.h"
#include "cheval/estim/rotor_model.h"

namespace cheval::estim {

/// A vehicle file for `estimate rotors` / `identify rotors` (JSON; docs/estimator_real_data.md has
/// the keys): the published constants and θ, with θ's standard deviations when identified.
struct RotorVehicle {
  std::string name, source;
  RotorNominal nominal;
  RotorThetaVector theta = RotorNominal::PublishedTheta();
  RotorThetaVector theta_sigma = RotorThetaVector::Zero();  ///< 0: not identified
  std::vector<std::string> training;                        ///< flights θ was identified on
};

/// Reads a rotor vehicle file. Throws InputError (`path:0:0: error: ...`) for an unreadable or
/// invalid file, an unknown, missing or non-numeric key, or a value out of its range.
RotorVehicle ReadRotorVehicle(const std::string& path);
/// The vehicle as JSON text, readable by ReadRotorVehicle.
std::string RotorVehicleToJson(const RotorVehicle& vehicle);

/// Options of EstimateRotors and IdentifyRotors (one set for every flight; the docs say why).
struct RotorEstimateOptions {
  int degree = 5;            ///< polynomial degree per segment, in [2, 20]
  double segment_s = 0.25;   ///< segment length, s (> 0)
  double position_sigma_m = 0.003;     ///< σ of a motion-capture position (> 0)
  double attitude_sigma_rad = 0.01;    ///< σ of the onboard attitude (> 0)
  double rate_sigma_radps = 0.05;      ///< σ of a body-rate sample (> 0)
  /// σ of a measured rotor speed in the identification, rad/s (> 0): the ESC's telemetry and the
  /// part of the rotor speeds the model does not explain (errors in variables, not held inputs).
  double rotor_sigma_radps = 30.0;
  double huber = 3.0;                  ///< Huber threshold of each measurement, in σ (> 0)
  /// Collocation σ (> 0): p' (m/s), v' (m/s²), ω' (rad/s²), body rate of R (rad/s).
  double sigma_position_rate = 1e-3, sigma_acceleration = 0.3, sigma_angular_acceleration = 3.0,
         sigma_rotation_rate = 1e-3;
  /// σ of the rotor-speed prior ∫ |Ω'|² dt / σ² (estimation only), rad/s² per s^(1/2) (> 0). The
  /// rotor error on each of the three Crazyflie flights is least at 700–1000 (docs/estimator_real_data.md).
  double sigma_rotor_rate = 1000.0;
  double baseline_window_s = 0.2;  ///< window of the flatness baseline's local fits, s (> 0)
  /// Identification: each flying span is cut into pieces of about this length (s, >= 1; a shorter
  /// span is one piece), identified one by one; their spread enters θ's σ (IdentifyRotors).
  double identification_piece_s = 8.0;
  double score_margin_s = 0.5;     ///< scored samples: flying, this far from a span's ends (>= 0)
  /// Estimation: estimate the offset δ between the onboard clock (attitude, body rates) and the motion
  /// capture's (positions; the rotor telemetry shares it) with the trajectory, and give the rotor
  /// speeds in the motion capture's time. On the shared flights the onboard samples arrive 0–30 ms
  /// late, differently on each (docs/estimator_real_data.md, "Two clocks"); kClockOffsetPriorSigmaS.
  bool estimate_clock_offset = true;
  /// Estimation: the accelerometer (`ax,ay,az`, the specific force in the world frame) as a
  /// measurement of the trajectory's acceleration, v' = g + a, with σ accelerometer_sigma_mps2 per
  /// axis (> 0) and the Huber loss, on the onboard clock. It carries the collective thrust through
  /// the motion capture's freezes (docs/estimator_real_data.md, "The accelerometer").
  bool use_accelerometer = true;
  double accelerometer_sigma_mps2 = 0.5;
  /// Levenberg–Marquardt iterations (>= 1). On the shared flights the rotor speeds after 6 iterations
  /// differ from those after 30 by < 0.1 % of the speed (docs/estimator_real_data.md).
  int max_iterations = 8;
  /// Ceres' relative cost-change tolerance (> 0). At 1e-2 the solver stops after 2–3 iterations from
  /// the flatness start; per-motor errors on the Crazyflie flights differ from those at 1e-3 (4–5
  /// iterations) by at most 0.035 points of % (docs/estimator_real_data.md). Ceres' default 1e-6
  /// spends 20–30 more on the Huber tails.
  double function_tolerance = 1e-2;
  /// Threads of the solver (>= 1): the machine's cores by default. The results do not depend on it.
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  /// Throws OptionError naming the first field out of its range.
  void Validate() const;
};

/// σ of the weak prior on the clock offset δ, s: it decides δ only where the motion does not (a hover).
/// The positions are expanded to second order in δ (internal/delayed_position_cost.h), good to 0.2 mm
/// up to |δ| = 30 ms at a jerk of 50 m/s³.
inline constexpr double kClockOffsetPriorSigmaS = 0.05;

/// Revolutions per minute in one rad/s: the rotor speeds are rad/s inside, rpm where people read them.
inline constexpr double kRpmPerRadps = 30.0 / std::numbers::pi;

/// Per-motor mean absolute error over the scored samples.
struct RotorError {
  Eigen::Vector4d rpm = Eigen::Vector4d::Zero();
  Eigen::Vector4d percent = Eigen::Vector4d::Zero();  ///< of the measured speed, per sample
};

/// The estimate at one sample of the flight.
struct RotorStateEstimate {
  double t = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector4d rotor = Eigen::Vector4d::Zero();     ///< estimated m1..m4, rad/s
  Eigen::Vector4d measured = Eigen::Vector4d::Zero();  ///< the flight's, rad/s
  Eigen::Vector4d baseline = Eigen::Vector4d::Zero();  ///< the flatness baseline's, rad/s
  bool scored = false;       ///< in the scored samples
};

/// What EstimateRotors returns.
struct RotorEstimate {
  RotorError error;                 ///< the estimate's
  RotorError baseline;              ///< the flatness baseline's, on the same samples
  double seconds = 0;               ///< wall time of the estimate (not of the baseline)
  double duration_s = 0;            ///< the estimated span(s), s
  int states = 0, segments = 0, iterations = 0, scored_samples = 0;
  /// Per flying span, the onboard clock minus the motion capture's (s): an instant the motion capture
  /// stamps t is stamped t + δ onboard (0 when not estimated).
  std::vector<double> clock_offsets_s;
  bool converged = false;
  std::vector<RotorStateEstimate> samples;  ///< at every sample inside a flying span
};

/// Rotor speeds m1..m4 (rad/s) at every sample by differential flatness with parameters θ: local
/// least-squares fits within `window_s` around each sample — quadratic of the fresh motion-capture
/// positions (a), linear of the body rates (ω') — then T = m (Rᵀ(a − g))_z (+ rotor drag), τ = Jω' +
/// ω × Jω − τ0 and the mixer inverted for Ω² (negative values give 0). With the published θ this is
/// the baseline of the issue: twice-differentiated positions and once-differentiated rates through the
/// published mixer.
std::vector<Eigen::Vector4d> FlatnessRotorSpeeds(const RotorFlight& flight, const RotorNominal& nominal,
                                                 const RotorThetaVector& theta, double window_s);

/// Per-motor mean absolute error of `estimate` against the measured speeds over `indices`.
RotorError ScoreRotors(const RotorFlight& flight, const std::vector<Eigen::Vector4d>& estimate,
                       const std::vector<size_t>& indices);

/// Estimates states and rotor speeds over each flying span of the flight, with θ known (the vehicle's),
/// without looking at the measured rotor speeds; scores them and the baseline. Throws OptionError for
/// bad options, ComputeError when no flying span is longer than 2 · score_margin_s + 0.1 s.
RotorEstimate EstimateRotors(const RotorFlight& flight, const RotorVehicle& vehicle, const RotorEstimateOptions& options);

/// θ identified from a piece of flight, or combined from several.
struct RotorIdentification {
  RotorThetaVector theta = RotorThetaVector::Zero();
  /// Scaled by the reduced χ² (each piece's); combined: by the dispersion too.
  Eigen::Matrix<double, kRotorThetaSize, kRotorThetaSize> covariance;
  /// Combined: each parameter's Birge ratio (>= 1), by which its σ was scaled.
  RotorThetaVector dispersion = RotorThetaVector::Ones();
  double reduced_chi2 = 0;  ///< combined: the largest of the pieces'
  double clock_offset_s = 0;  ///< the onboard clock minus the motion capture's (combined: the pieces' mean)
  double seconds = 0;
  int pieces = 0;
  bool converged = false;
};

/// Per parameter, the Birge ratio max(1, sqrt(Q / (k − 1))) of k identifications about θ, Q = Cochran's
/// Σ (θ_k − θ)² / σ²_k; 1 for a held parameter (zero variance) or fewer than two.
RotorThetaVector BirgeRatios(const std::vector<RotorIdentification>& groups, const RotorThetaVector& theta);

/// Combines identifications by their information (the product of their Gaussians), then scales each
/// parameter's σ by its Birge ratio sqrt(Q / (k − 1)) when above 1, Q = Cochran's Σ (θ_piece − θ)² /
/// σ²_piece: the σ then covers how far apart the pieces are, not only how well each determines θ
/// (Birge 1932; the pieces' residuals are correlated in time, which each piece's covariance ignores).
/// One piece: returned as it is. UsageError when empty.
RotorIdentification CombineIdentifications(const std::vector<RotorIdentification>& pieces);

/// Identifies θ jointly with the trajectory and rotor speeds (the measured rotor speeds as
/// measurements with σ rotor_sigma_radps; a weak prior keeps θ within reach of the published
/// vehicle: σ 1 on the relative entries, 100 units on the others) on each piece of about
/// identification_piece_s of every flying span, and combines the pieces by CombineIdentifications:
/// θ's σ then holds how much θ changes from one stretch of flight to another, which the solver's
/// covariance alone (residuals taken as independent) does not; with several flights it is widened
/// again by the flights' Birge ratio (each flight's pieces combined, about the combined θ), for what
/// changes from one flight to another. Returns the vehicle with the combined θ and σ, and
/// `per_flight` each flight's own combination. ComputeError when a covariance cannot be
/// computed.
RotorVehicle IdentifyRotors(const std::vector<RotorFlight>& flights, const RotorVehicle& base,
                            const RotorEstimateOptions& options, std::vector<RotorIdentification>* per_flight);

}  // namespace cheval::estim

namespace cheval::estim {

/// The `estimate rotors --json` object: `rotor_error_percent`, `flatness_error_percent` (4 each, m1..m4),
/// `rotor_error_rpm`, `flatness_error_rpm`, `seconds`, `duration_s`, `states`, `segments`,
/// `iterations`, `converged`, `scored_samples`, `dropped_rows` (file lines of rows with missing
/// values), `flying_spans` ([first, last] s each) and `clock_offsets_s` (one per span).
std::string RotorEstimateJson(const RotorEstimate& estimate, const RotorFlight& flight);

/// The `-o` CSV: `t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz` (estimated; world position and velocity,
/// R_world_body, body rate), `rotor1..4` (estimated, rad/s), `measured1..4`, `baseline1..4` (the
/// flatness baseline), `scored` (1 for the scored samples): one row per sample inside a flying span,
/// everything a figure of estimated against measured speeds per motor needs.
std::string RotorStatesCsv(const RotorEstimate& estimate);

}  // namespace cheval::estim

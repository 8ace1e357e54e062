#pragma once
/// \file
/// Synthetic motion with exact derivatives, for tests, demos and benchmarks (docs/sim.md).
///
/// Every kind of motion is an analytic function of time. Positions p_world_body (m), world-frame
/// velocities (m/s), orientations R_world_body and body-frame angular velocities (rad/s) are exact to
/// rounding: derivatives come from truncated Taylor arithmetic (forward-mode differentiation of the
/// closed forms), never from finite differences, and positions that are the integral of a designed
/// velocity come from composite 16-point Gauss–Legendre quadrature, whose error on these smooth,
/// slow integrands is far below double rounding. Frames: world z up; body x forward, y left, z up.
///
/// A MotionModel is the function of time; GenerateMotion samples it on its nominal grid (the truth),
/// SampleMotion at any stamps, and Measure makes the measured copy: irregular (jittered) stamps,
/// dropouts and gaps, with positions equal to the truth at each measured stamp plus Gaussian noise.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "cheval/traj/trajectory.h"

namespace cheval::sim {

/// Kinds of synthetic motion (docs/sim.md has the formulas and parameter ranges of each).
enum class MotionKind {
  kCar,       ///< road vehicle: 1.5–14.5 m/s with accelerations and brakings, smooth curvature,
              ///< heading along the velocity, road grade, roll and pitch from the accelerations
  kLegged,    ///< trotting quadruped body: ~0.35–0.9 m/s forward, 2–3 Hz vertical and lateral
              ///< oscillation, roll/pitch/yaw oscillation at the gait frequency
  kDrone,     ///< multirotor flying a figure-eight Lissajous with a peak speed of 8 m/s, yaw along the
              ///< path, roll/pitch tilting the thrust axis along acceleration + gravity
  kHandheld,  ///< camera carried by a walking person: wandering ~1 m/s path, 1.5–2 Hz step bounce of
              ///< 2–4 cm, large yaw and pitch sweeps (peak body rates ~1.3–2 rad/s)
};

/// The kind's name as the CLI spells it: "car", "legged", "drone", "handheld".
std::string_view ToString(MotionKind kind);
/// Parses a kind name as ToString spells it; nullopt if unknown.
std::optional<MotionKind> MotionKindFromString(std::string_view name);

/// Default duration and sampling rate of a kind's nominal grid.
struct MotionDefaults {
  double duration_s;  ///< seconds
  double rate_hz;     ///< samples per second
};

/// Defaults of `kind`: car 100 s at 50 Hz, legged 10 s at 200 Hz, drone 60 s at 200 Hz, handheld
/// 30 s at 100 Hz.
MotionDefaults DefaultsFor(MotionKind kind);

/// What to generate. Validated when a MotionModel is built (with the kind's defaults filled in).
struct MotionOptions {
  MotionKind kind = MotionKind::kDrone;                ///< one of the MotionKind values
  std::optional<double> duration_s;                    ///< > 0 and <= 1e6 s; nullopt: the kind's default
  std::optional<double> rate_hz;                       ///< > 0 Hz; nullopt: the kind's default
  int64_t start_stamp_ns = 1'403'636'580'000'000'000;  ///< stamp of t = 0 (EuRoC-like epoch), |.| <= 4e18
  uint64_t seed = 1;  ///< draws the shape's random parameters and every measurement effect

  /// Throws OptionError naming the first bad field: a kind outside MotionKind; a duration that is
  /// not positive and finite or above 1e6 s; a rate that is not positive and finite; a duration ×
  /// rate grid of more than 1e8 samples (when both are set); a start stamp outside ±4e18 ns.
  void Validate() const;
};

/// How the measured copy differs from the truth (Measure). Every effect has its own random stream
/// derived from MotionOptions::seed, so e.g. changing the noise does not move the dropouts.
struct MeasurementOptions {
  double noise_m = 0.0;  ///< σ of N(0, σ²) added to each position coordinate, metres, >= 0
  /// σ in seconds of the Gaussian offset added to each nominal stamp (>= 0, < duration).
  /// The jittered stamps are rounded to the nanosecond, sorted, and each one not above its
  /// predecessor is moved to predecessor + 1 ns, so stamps strictly increase; positions are the truth
  /// at the final stamps, so the order change (only when σ is a sizeable part of the period) costs
  /// no exactness.
  double jitter_s = 0.0;
  double dropout_probability = 0.0;  ///< each nominal sample is dropped with this probability, [0, 1)
  /// Number of longer gaps. The duration is cut into gap_count equal slots and one gap
  /// of gap_s is placed uniformly at random inside each slot, one nominal period away from the slot
  /// ends; nominal samples with stamp offset in [start, start + gap_s) are removed. >= 0.
  int gap_count = 0;
  double gap_s = 0.0;  ///< length of each gap, > 0 exactly when gap_count > 0 (else 0)
  /// σ in radians of the body-frame perturbation of each measured orientation,
  /// R_measured = R·Exp(n) with n ~ N(0, σ²I₃) (>= 0; motion capture: ~0.002-0.01 rad).
  double rotation_noise_rad = 0.0;

  /// Throws OptionError naming the first bad field: a negative or non-finite noise_m, jitter_s or
  /// rotation_noise_rad; a dropout_probability outside [0, 1); a negative gap_count; a gap_s that is
  /// not positive and finite when gap_count > 0, or not 0 when it is 0. (The rules that need the
  /// model's duration are Measure's.)
  void Validate() const;
};

/// The exact state at one time.
struct MotionState {
  Eigen::Vector3d position;          ///< p_world_body, m
  Eigen::Quaterniond orientation;    ///< R_world_body, unit norm (sign: as Eigen converts the matrix)
  Eigen::Vector3d velocity;          ///< d/dt p_world_body in the world frame, m/s
  Eigen::Vector3d angular_velocity;  ///< ω with Ṙ = R [ω]×, body frame, rad/s
};

/// One kind of motion with its random parameters fixed by the seed: an exact function of time,
/// defined for every time (also before the start and after the duration). Cheap to copy (shared,
/// immutable state); safe to evaluate from several threads.
class MotionModel {
 public:
  /// Fills in the kind's default duration and rate where they are unset, validates the result
  /// (MotionOptions::Validate: OptionError, e.g. "MotionOptions::rate_hz must be a positive number of
  /// Hz, got -1") and draws the kind's parameters from `options.seed`.
  explicit MotionModel(const MotionOptions& options);

  /// The options with the defaults filled in: duration_s and rate_hz always hold a value.
  const MotionOptions& options() const;
  /// The kind of motion (options().kind).
  MotionKind kind() const { return options().kind; }

  /// The exact state at `stamp_ns` (t = (stamp_ns - start_stamp_ns) · 1e-9 s, the difference taken
  /// in int64, so it must not overflow: any stamp within ±5e18 ns qualifies).
  MotionState StateAt(int64_t stamp_ns) const;
  /// The exact state at `t_s` seconds after start_stamp_ns.
  MotionState StateAtTime(double t_s) const;

  /// The nominal grid: start_stamp_ns + round(i · 1e9 / rate_hz) ns for i = 0 .. floor(duration ·
  /// rate) (so the last sample is at or just before the duration).
  std::vector<int64_t> NominalStamps() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

/// The exact truth at arbitrary `stamps_ns` (any order; duplicates allowed): positions, unit
/// quaternions, world-frame velocities and body angular velocities. Quaternion signs are kept
/// continuous along the given order (each one has a non-negative dot product with its predecessor;
/// the first has w >= 0), as a tracker would report them.
traj::Trajectory SampleMotion(const MotionModel& model, std::span<const int64_t> stamps_ns);

/// The truth on the model's nominal grid: SampleMotion(model, model.NominalStamps()).
traj::Trajectory GenerateMotion(const MotionModel& model);
/// GenerateMotion(MotionModel(options)). Throws OptionError as MotionModel does.
traj::Trajectory GenerateMotion(const MotionOptions& options);

/// The measured copy of `model` (positions and quaternions; no velocity channels): nominal grid
/// samples are removed by the gaps and dropouts, the survivors' stamps jittered (see
/// MeasurementOptions::jitter_s), and each position is the exact truth at its final stamp plus
/// N(0, noise_m²) per coordinate; orientations are the truth perturbed by rotation_noise_rad.
/// Deterministic in the model's seed. Throws OptionError naming the field: what
/// MeasurementOptions::Validate rejects, a jitter_s not below the duration, gaps that do not fit in
/// the duration (gap_s + 2 / rate must be below duration / gap_count), or dropout_probability when
/// fewer than 2 samples would remain.
traj::Trajectory Measure(const MotionModel& model, const MeasurementOptions& measurement);

/// How a simulated state estimator (a visual-inertial odometry, say) errs: what the CLI's simulated
/// estimates are (docs/sim.md), so that evaluation (APE, RPE, ASE) and reports can be shown on data cheval
/// makes itself. The errors drift as an odometry's do: the velocity error b(t) is a random walk,
/// the position error is its integral plus white noise (so position drift and velocity error are
/// consistent, as in a filter), and the orientation error is a random walk on SO(3).
struct EstimatorSimOptions {
  double rate_hz = 20.0;                    ///< output rate, > 0 Hz
  double velocity_random_walk = 0.002;      ///< σ of b's random walk, m/s per √s, >= 0
  double position_noise_m = 0.002;          ///< white noise on each position coordinate, m, >= 0
  double velocity_noise_mps = 0.005;        ///< white noise on each velocity coordinate, m/s, >= 0
  double rotation_random_walk_rad = 0.002;  ///< σ of the orientation error's random walk, rad per √s, >= 0
  double delay_s = 0.0;                     ///< stamps start this long after the truth's start, [0, duration)
  uint64_t stream = 0;                      ///< distinguishes several estimates of one model and seed

  /// Throws OptionError naming the first bad field: a rate_hz that is not positive and finite, a
  /// negative or non-finite σ, or a negative or non-finite delay_s. (The rules that need the model's
  /// duration are SimulateEstimate's.)
  void Validate() const;
};

/// A simulated estimator's output for `model`: TUM + velocity (positions, R_world_body quaternions,
/// world-frame velocities) at options.rate_hz from the model's start (+ delay_s) to its duration,
/// with the errors of EstimatorSimOptions, starting from zero error. Deterministic in the model's
/// seed and options.stream. Throws OptionError naming the field: what EstimatorSimOptions::Validate
/// rejects, a delay_s not below the duration, or a rate_hz giving fewer than 2 or more than 1e8 poses.
traj::Trajectory SimulateEstimate(const MotionModel& model, const EstimatorSimOptions& options);

/// A copy of any `truth` without velocity channels and with N(0, sigma_m²) noise on every position
/// coordinate (metres), drawn from a generator seeded with `seed`; stamps and orientations are kept.
/// Throws UsageError unless sigma_m is finite and >= 0.
traj::Trajectory AddPositionNoise(const traj::TrajectoryView& truth, double sigma_m, uint64_t seed);

}  // namespace cheval::sim

#pragma once
/// \file
/// States and rotor speeds of a quadrotor from a monocular camera seeing known landmarks and the
/// dynamics alone (Agrawal & Dellaert, ICRA 2021, §IV; docs/estimator.md). The inputs are what a
/// real system has: the vehicle file, the landmark map, pixel measurements and the initial poses of
/// a visual-odometry front end. States and rotor speeds start from a flatness-based fit of those
/// poses (FlatnessInitialState).

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "cheval/common/progress.h"
#include "cheval/estim/vehicle.h"

namespace cheval::estim {

/// One pixel measurement of a landmark at a frame time.
struct PixelObservation {
  double t = 0;        ///< s
  int landmark = 0;    ///< index into the landmark list
  Eigen::Vector2d uv;  ///< pixel (u, v)
};

/// A pose (R_world_body, p_world_body) at a time: the front end's initial estimates.
struct PoseSample {
  double t = 0;
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
};

/// Defaults chosen once for every scenario (docs/estimator.md explains them).
struct QuadrotorEstimateOptions {
  /// --degree: polynomial degree per segment (>= 2). --segment: segment length, s (> 0); the flight
  /// is cut into round(T / segment_s) segments. Short, low-degree segments because the priors' σ are
  /// estimated per segment: 0.2 s resolves where the thrust changes fast (docs/estimator.md,
  /// "Segments").
  int degree = 4;
  double segment_s = 0.2;
  /// σ of the collocation defects: p' (m/s), v' (m/s²), ω' (rad/s²), body rate of R (rad/s).
  double sigma_position_rate = 1e-3, sigma_acceleration = 1e-2, sigma_angular_acceleration = 1e-1,
         sigma_rotation_rate = 1e-3;
  /// σ of the rotor-speed smoothness prior ∫ |Ω^(m)|² dt / σ² (AddControlSmoothnessPrior, exact per
  /// segment), rad/s per s^m per s^(1/2); 0 = none.
  double sigma_rotor_rate = 100.0;
  /// m of that prior: 1 = white noise on the rotor rate Ω' (Ω a random walk), 2 = on Ω'' (1..3).
  int rotor_prior_order = 1;
  /// Empirical Bayes for that prior's σ per segment (order 1 only; docs/estimator.md): a pilot solve
  /// of `pilot_iterations` Levenberg–Marquardt iterations with sigma_rotor_rate everywhere, then
  /// σ_s = max(floor, AdaptiveRotorPriorSigma), the maximum-likelihood random-walk intensity of the
  /// pilot's rotor speeds over segments s − 1..s + 1, and the solve to convergence. false: one solve
  /// with sigma_rotor_rate everywhere.
  bool adaptive_rotor_prior = true;
  int pilot_iterations = 1;                ///< Levenberg–Marquardt iterations of the pilot solve (>= 1)
  double adaptive_rotor_prior_floor = 30;  ///< lower bound of the per-segment σ, rad/s² per s^(1/2) (> 0)
  /// The collective rotor speed's prior on the world-frame thrust acceleration instead
  /// (docs/estimator.md, "Defaults"; needs adaptive_rotor_prior): after the pilot, the collective
  /// component of the rotor-rate prior is dropped and a = f − ḡ, f = (k_F ΣΩ²/m) R e3, ḡ the hover
  /// thrust, gets ∫ |(D + λ_a)² a_a|² dt / σ_s² per axis a (a Matérn-3/2 process: a stationary
  /// acceleration of correlation time 1/λ_a) with λ_a the root-mean-square frequency of the pilot's
  /// a_a (sqrt(−∫a''a / ∫a²), at most thrust_prior_max_rate rad/s), σ_s the maximum-likelihood
  /// intensity of segment s alone, f' continuous at the breakpoints, and the stationary law of
  /// (a, a') at the first time (the exact density of the stationary process). The differential
  /// (roll, pitch, yaw) components keep the random-walk prior with the per-segment σ above.
  bool thrust_prior = true;
  double thrust_prior_max_rate = 6.0;  ///< rad/s (> 0): the bound of λ_a on an axis without motion
  /// Empirical-Bayes rounds of the thrust prior (>= 1): after each solve with it, λ_a and σ_s are
  /// re-estimated from that solution and the problem is solved again (1: from the pilot only).
  /// These three options are measured variants, not the defaults (docs/estimator.md, "Closing the
  /// last two aggressive seeds": none gets the aggressive flight under 0.5 % on every seed).
  int thrust_prior_rounds = 1;
  /// Order m of the thrust prior (2 or 3; motion_prior too): ∫ |(D + λ_a)^m a_a|² dt, 2 a
  /// Matérn-3/2 process, 3 a Matérn-5/2 one (λ_a = √3 × the rms frequency, f'' continuous as well, its stationary law of
  /// (a, a', a'') at the first time).
  int thrust_prior_order = 2;
  /// The Matérn-3/2 prior of thrust_prior on the kinematic acceleration v' (a motion prior; the
  /// collective follows through the collocation of v' = f − g − drag) instead of on f − ḡ.
  bool motion_prior = false;
  double huber_pixels = 3.0;  ///< Huber threshold on each landmark's whitened pixel error (in σ)
  /// Window of the flatness-based initialisation (FlatnessInitialState), s (> 0).
  double initial_window_s = 0.6;
  /// Levenberg–Marquardt's initial trust-region radius (1/λ₀; Ceres' default is 1e4). The problem is
  /// nearly linear from the flatness-based start, so a near Gauss–Newton first step is accepted:
  /// 3–4 iterations instead of 6–7, the same minimum (docs/estimator.md).
  double initial_trust_region_radius = 1e8;
  int max_iterations = 50;
  /// Ceres' convergence tolerances (its defaults): relative cost change, gradient, step. Tighter
  /// ones change nothing (the solve is converged: docs/estimator.md).
  double function_tolerance = 1e-6, gradient_tolerance = 1e-10, parameter_tolerance = 1e-8;
  int threads = 1;
  /// Told "solver iterations" with the iterations done so far (total unknown: 0), after each one.
  ProgressFn progress;
};

/// The estimate at one time.
struct QuadrotorStateEstimate {
  double t = 0;
  Eigen::Vector3d p, v, w;
  Eigen::Matrix3d R;
  Eigen::Vector4d rotor;  ///< rad/s
};

/// What EstimateQuadrotor returns.
struct QuadrotorEstimate {
  int states = 0;     ///< Chebyshev nodes (segments · degree + 1), each a full state and control
  int segments = 0;
  int degree = 0;
  int iterations = 0;  ///< Levenberg–Marquardt iterations, the pilot's and the final solve's together
  double seconds = 0;         ///< wall time of building and solving the problem
  bool converged = false;     ///< Ceres reported CONVERGENCE
  std::string solver_report;  ///< Ceres' brief report (of the final solve)
  std::string solver_full_report;  ///< Ceres' full report (with the time of each stage)
  double start_time = 0, end_time = 0;
  std::vector<QuadrotorStateEstimate> samples;  ///< at the requested times inside [start, end]
};

/// The initial state and rotor speeds at time t from the front end's poses (sorted by time, at
/// least 3), by the quadrotor's differential flatness (Mellinger & Kumar, ICRA 2011): a least-squares
/// quadratic fit of the positions within a window of `window_s` around t (shifted inside the poses'
/// span near its ends) gives p, v = p' and a = p''; R is the front end's rotation at t (slerp); the
/// body rate ω is the slope of a linear fit of Log(R⁻¹ R_i) over the same window; the collective
/// thrust is T = (m (a − g) + c |v| v) · R e3 and the torques τ = ω × Jω (ω' is taken as 0: the
/// front end's attitude noise makes its second derivative useless); the rotor speeds invert the
/// mixer of ESTIMATOR.md exactly, sqrt(max(f_i, 0) / k_F), capped at the rotor limit. Nothing but
/// the poses and the vehicle file is used. Throws ComputeError with fewer than 3 poses.
QuadrotorStateEstimate FlatnessInitialState(const QuadrotorParameters& vehicle, const std::vector<PoseSample>& poses,
                                            double t, double window_s);

/// The maximum-likelihood σ of a white-noise-on-u' (random-walk) prior for each segment from
/// `energy[s]` = ∫_s |u'|² dt of a pilot estimate (summed over `controls` entries) on segments of
/// `degree`: with n increments of a random walk of intensity σ², Σ (Δu)²/Δt ≈ ∫ |u'|² has mean σ² n,
/// so σ̂² = ∫ |u'|² / n with n = controls · degree per segment. Pooled over the segment and its
/// neighbours (s − 1, s, s + 1 where they exist: 2–3 segments, 8–12 increments per control at the
/// default degree 4), since one segment's estimate would be too noisy. Throws UsageError for degree < 1,
/// controls < 1 or a negative energy.
std::vector<double> AdaptiveRotorPriorSigma(const std::vector<double>& energy, int degree, int controls);

/// Estimates the flight over [first, last] measurement time and returns it at `query_times` (those
/// outside the interval are skipped). Throws UsageError for bad options, ComputeError when there are
/// fewer than 2 frame times or 3 initial poses, a landmark id is out of range, the initial poses do
/// not cover the measurement interval, or a measurement falls outside the estimated interval.
QuadrotorEstimate EstimateQuadrotor(const Vehicle& vehicle, const std::vector<Eigen::Vector3d>& landmarks,
                                    const std::vector<PixelObservation>& pixels,
                                    const std::vector<PoseSample>& initial, const QuadrotorEstimateOptions& options,
                                    const std::vector<double>& query_times);

}  // namespace cheval::estim

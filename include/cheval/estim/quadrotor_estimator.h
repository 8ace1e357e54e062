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

/// The estimator's options, one default set for every scenario (docs/estimator.md, "The algorithm", says
/// why each is what it is). The estimator runs: a pilot solve with the rotor prior at
/// sigma_rotor_rate everywhere → σ of the rotor prior per segment from the pilot (empirical Bayes) →
/// the solve to convergence.
struct QuadrotorEstimateOptions {
  /// Polynomial degree per segment, in [2, 64].
  int degree = 4;
  /// Segment length, s (> 0): the flight is cut into round(T / segment_s) segments. Short segments
  /// because the priors' σ are estimated per segment.
  double segment_s = 0.2;
  /// σ of the collocation defects (> 0): p' (m/s), v' (m/s²), ω' (rad/s²), body rate of R (rad/s).
  double sigma_position_rate = 1e-3, sigma_acceleration = 1e-2, sigma_angular_acceleration = 1e-1,
         sigma_rotation_rate = 1e-3;
  /// σ of the pilot's rotor-speed prior ∫ |Ω'|² dt / σ² on every segment, rad/s² per s^(1/2) (> 0).
  double sigma_rotor_rate = 100.0;
  /// Levenberg–Marquardt iterations of the pilot solve (>= 1).
  int pilot_iterations = 1;
  /// Lower bound of the per-segment σ of the rotor prior after the pilot, σ_s = max(floor,
  /// AdaptiveRotorPriorSigma), rad/s² per s^(1/2) (> 0).
  double rotor_prior_sigma_floor = 30;
  /// After the pilot, the collective rotor speed's prior is the Matérn-3/2 prior on the world-frame
  /// thrust acceleration (docs/estimator.md, "The algorithm", step 5); the differential (roll,
  /// pitch, yaw) components keep the rotor prior. false: the collective keeps the rotor prior too.
  bool thrust_prior = true;
  double thrust_prior_max_rate = 6.0;  ///< rad/s (> 0): the bound of the thrust prior's λ_a
  double huber_pixels = 3.0;  ///< Huber threshold on each landmark's whitened pixel error, in σ (> 0)
  /// Window of the flatness-based initialisation (FlatnessInitialState), s (> 0).
  double initial_window_s = 0.6;
  /// Levenberg–Marquardt's initial trust-region radius (> 0; Ceres' default is 1e4): the problem is
  /// nearly linear from the flatness-based start, so a near Gauss–Newton first step is accepted.
  double initial_trust_region_radius = 1e8;
  int max_iterations = 50;  ///< of the final solve (>= 1)
  /// Ceres' convergence tolerances (its defaults; > 0): relative cost change, gradient, step.
  double function_tolerance = 1e-6, gradient_tolerance = 1e-10, parameter_tolerance = 1e-8;
  int threads = 1;  ///< >= 1
  /// Told "solver iterations" with the iterations done so far (total unknown: 0), after each one.
  ProgressFn progress;

  /// Throws OptionError naming the first field out of its range (above).
  void Validate() const;
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
/// mixer of models.h exactly, sqrt(max(f_i, 0) / k_F), capped at the rotor limit. Nothing but
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
/// outside the interval are skipped). Throws OptionError for bad options, ComputeError when there are
/// fewer than 2 frame times or 3 initial poses, a landmark id is out of range, the initial poses do
/// not cover the measurement interval, or a measurement falls outside the estimated interval.
QuadrotorEstimate EstimateQuadrotor(const Vehicle& vehicle, const std::vector<Eigen::Vector3d>& landmarks,
                                    const std::vector<PixelObservation>& pixels,
                                    const std::vector<PoseSample>& initial, const QuadrotorEstimateOptions& options,
                                    const std::vector<double>& query_times);

}  // namespace cheval::estim

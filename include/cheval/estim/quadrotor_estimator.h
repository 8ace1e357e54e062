#pragma once
/// \file
/// States and rotor speeds of a quadrotor from a monocular camera seeing known landmarks and the
/// dynamics alone (Agrawal & Dellaert, ICRA 2021, §IV; docs/estimator.md). The inputs are what a
/// real system has: the vehicle file, the landmark map, pixel measurements and the initial poses of
/// a visual-odometry front end. Rotor speeds start at the hover speed of the vehicle file.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

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
  int degree = 10;          ///< --degree: polynomial degree per segment (>= 2)
  double segment_s = 1.0;   ///< --segment: segment length, s (> 0); the flight is cut into round(T / segment_s) segments
  /// σ of the collocation defects: p' (m/s), v' (m/s²), ω' (rad/s²), body rate of R (rad/s).
  double sigma_position_rate = 1e-3, sigma_acceleration = 1e-2, sigma_angular_acceleration = 1e-1,
         sigma_rotation_rate = 1e-3;
  /// σ of the rotor-speed smoothness prior (AddControlRatePrior), rad/s² per s^(1/2); 0 = none.
  double sigma_rotor_rate = 100.0;
  double huber_pixels = 3.0;  ///< Huber threshold on each landmark's whitened pixel error (in σ)
  int max_iterations = 50;
  int threads = 1;
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
  int iterations = 0;
  double seconds = 0;         ///< wall time of building and solving the problem
  bool converged = false;     ///< Ceres reported CONVERGENCE
  std::string solver_report;  ///< Ceres' brief report
  double start_time = 0, end_time = 0;
  std::vector<QuadrotorStateEstimate> samples;  ///< at the requested times inside [start, end]
};

/// Estimates the flight over [first, last] measurement time and returns it at `query_times` (those
/// outside the interval are skipped). Throws UsageError for bad options, ComputeError when there are
/// fewer than 2 frame times, a landmark id is out of range, the initial poses do not cover the
/// measurement interval, or a measurement falls outside the estimated interval.
QuadrotorEstimate EstimateQuadrotor(const Vehicle& vehicle, const std::vector<Eigen::Vector3d>& landmarks,
                                    const std::vector<PixelObservation>& pixels,
                                    const std::vector<PoseSample>& initial, const QuadrotorEstimateOptions& options,
                                    const std::vector<double>& query_times);

}  // namespace cheval::estim

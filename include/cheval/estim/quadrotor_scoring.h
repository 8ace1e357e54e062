#pragma once
/// \file
/// How a quadrotor estimate is reported and scored (docs/estimator.md): the times it is reported
/// at, its errors against a ground truth, its states in truth.csv's layout and the JSON object of
/// `cheval estimate quadrotor --json` (and of the Python module).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "cheval/estim/quadrotor_data.h"
#include "cheval/estim/quadrotor_estimator.h"

namespace cheval::estim {

/// Errors of an estimate against the ground truth at the truth samples inside the estimated interval.
struct QuadrotorErrors {
  int samples = 0;
  Eigen::Vector4d rotor_error_rpm = Eigen::Vector4d::Zero();      ///< mean |Ω̂_i − Ω_i| per motor, rpm
  Eigen::Vector4d rotor_error_percent = Eigen::Vector4d::Zero();  ///< the same, % of the motor's mean true speed
  double position_rmse_m = 0, rotation_rmse_deg = 0, velocity_rmse_mps = 0;
};

/// Compares an estimate with the truth at the truth samples (the estimate is re-interpolated there:
/// pass the truth times as query times to EstimateQuadrotor; samples match within 1e-9 s). Rotation
/// error: |Log(R̂ᵀ R)|. ComputeError when no sample overlaps.
QuadrotorErrors CompareWithTruth(const QuadrotorEstimate& estimate, const std::vector<QuadrotorTruth>& truth);

/// The times an estimate of `data` is reported at: the truth's times when the data has a truth (so
/// CompareWithTruth can use them), else every 10 ms from the first front-end pose to the last.
std::vector<double> ReportTimes(const QuadrotorData& data);

/// The states of an estimate in the layout of QuadrotorTruth (its samples, in time order).
std::vector<QuadrotorTruth> EstimatedStates(const QuadrotorEstimate& estimate);

/// The JSON object of `cheval estimate quadrotor --json` (docs/estimator.md): states, segments,
/// degree, iterations, seconds, converged and, when `errors` is given, rotor_error_rpm,
/// rotor_error_percent (4 numbers each), position_rmse_m, rotation_rmse_deg, velocity_rmse_mps.
/// The Python module returns the same object as a dict.
std::string QuadrotorEstimateJson(const QuadrotorEstimate& estimate, const QuadrotorErrors* errors);

}  // namespace cheval::estim

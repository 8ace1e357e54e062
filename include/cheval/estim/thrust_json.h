#pragma once
/// \file
/// The JSON of a collective-thrust estimate (`cheval estimate thrust --json`, docs/estimator_real_data.md).

#include <string>

#include "cheval/estim/thrust_estimator.h"

namespace cheval::estim {

/// The JSON object of `cheval estimate thrust --json`: samples, position_measurements,
/// imu_measurements, states, segments, degree, iterations, converged, seconds, mean_measured_rpm,
/// collective_error_rpm, collective_error_percent, collective_rmse_rpm, collective_bias_rpm, the
/// baselines baseline_flatness and baseline_accelerometer and the oracle model_floor (each with
/// mean_abs_rpm, mean_abs_percent, rmse_rpm, bias_rpm), position_rmse_m and velocity_rmse_mps;
/// two-space indented, with a final newline.
std::string ThrustEstimateJson(const ThrustEstimate& estimate);

}  // namespace cheval::estim

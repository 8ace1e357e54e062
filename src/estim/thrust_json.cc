#include "cheval/estim/thrust_json.h"

#include <nlohmann/json.hpp>

namespace cheval::estim {
namespace {

nlohmann::json ErrorsJson(const CollectiveErrors& e) {
  return {{"mean_abs_rpm", e.mean_abs_rpm}, {"mean_abs_percent", e.mean_abs_percent}, {"rmse_rpm", e.rmse_rpm},
          {"bias_rpm", e.bias_rpm}};
}

}  // namespace

std::string ThrustEstimateJson(const ThrustEstimate& e) {
  const nlohmann::json j = {{"samples", e.estimate.samples},
                            {"position_measurements", e.position_measurements},
                            {"imu_measurements", e.imu_measurements},
                            {"states", e.states},
                            {"segments", e.segments},
                            {"degree", e.degree},
                            {"iterations", e.iterations},
                            {"converged", e.converged},
                            {"seconds", e.seconds},
                            {"mean_measured_rpm", e.mean_measured_rpm},
                            {"collective_error_rpm", e.estimate.mean_abs_rpm},
                            {"collective_error_percent", e.estimate.mean_abs_percent},
                            {"collective_rmse_rpm", e.estimate.rmse_rpm},
                            {"collective_bias_rpm", e.estimate.bias_rpm},
                            {"baseline_flatness", ErrorsJson(e.flatness)},
                            {"baseline_accelerometer", ErrorsJson(e.accelerometer)},
                            {"model_floor", ErrorsJson(e.model_floor)},
                            {"position_rmse_m", e.position_rmse_m},
                            {"velocity_rmse_mps", e.velocity_rmse_mps}};
  return j.dump(2) + "\n";
}

}  // namespace cheval::estim

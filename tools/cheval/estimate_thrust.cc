// `cheval estimate thrust`: the collective rotor speed of a real DIDO flight from positions (and the
// accelerometer with --imu), the measured attitude and the translational dynamics, compared with the
// measured rotor speeds (docs/estimator_real_data.md).
#include <fmt/format.h>

#include <memory>
#include <string>

#include "cheval/common/error.h"
#include "cheval/estim/thrust_estimator.h"
#include "cheval/estim/thrust_json.h"
#include "common.h"

namespace cheval::cli {
namespace {

struct ThrustFlags {
  std::string data;
  std::string params;
  std::string json;
  estim::ThrustEstimateOptions options;
};

void PrintErrors(const char* label, const estim::CollectiveErrors& e) {
  fmt::print("{:<28}{:8.1f} rpm {:7.3f} %   RMSE {:8.1f} rpm   bias {:+8.1f} rpm\n", label, e.mean_abs_rpm,
             e.mean_abs_percent, e.rmse_rpm, e.bias_rpm);
}

}  // namespace

void RegisterEstimateThrust(CLI::App& app, Action* action) {
  CLI::App* estimate = app.get_subcommand("estimate");
  auto flags = std::make_shared<ThrustFlags>();
  estim::ThrustEstimateOptions& o = flags->options;
  CLI::App* thrust = estimate->add_subcommand(
      "thrust", "Collective rotor speed of a real quadrotor (DIDO CSV) from positions (+ IMU) and the translational dynamics");
  thrust->add_option("--data", flags->data, "DIDO sequence CSV (../shared/data/dido/csv/NAME.csv)")->required();
  thrust->add_option("--params", flags->params, "Its identified parameters (default: NAME.dynamic_params.csv)");
  thrust->add_option("--degree", o.degree, "Polynomial degree per segment")->capture_default_str();
  thrust->add_option("--segment", o.segment_s, "Segment length (s)")->capture_default_str();
  thrust->add_flag("--imu", o.use_imu, "Also use the accelerometer (every sample)");
  thrust->add_option("--position-rate", o.position_rate_hz, "Rate of the position measurements used (Hz)")
      ->capture_default_str();
  thrust->add_option("--position-sigma", o.position_sigma_m, "Sigma of a position measurement (m)")->capture_default_str();
  thrust->add_option("--position-noise", o.position_noise_m, "White noise added to the positions used (m)")
      ->capture_default_str();
  thrust->add_option("--seed", o.seed, "Seed of that noise")->capture_default_str();
  thrust->add_option("--imu-sigma", o.imu_sigma_mps2, "Sigma of one accelerometer sample per axis (m/s^2)")
      ->capture_default_str();
  thrust->add_option("--sigma-acceleration", o.sigma_acceleration, "Collocation sigma of v' (m/s^2)")
      ->capture_default_str();
  thrust->add_option("--sigma-rotor-rate", o.sigma_rotor_rate,
                     "Smoothness prior of the collective (rad/s^2 per s^0.5; 0 = none)")
      ->capture_default_str();
  thrust->add_option("--rotor-delay", o.rotor_delay_s,
                     "Compare with the rotor-speed log shifted by this delay (s; evaluation only)")
      ->capture_default_str();
  thrust->add_option("--json", flags->json, "Write the result as JSON");
  thrust->callback([flags, action] {
    *action = [flags] {
      RefuseSharedPaths({flags->data, flags->params}, {{"--json", flags->json}});
      const estim::ThrustFlight flight = estim::ReadDidoFlight(flags->data, flags->params);
      const estim::ThrustEstimate e = estim::EstimateThrust(flight, flags->options);
      fmt::print("samples             {}\nposition meas.      {} ({} Hz, sigma {} m, added noise {} m)\n",
                 e.estimate.samples, e.position_measurements, flags->options.position_rate_hz,
                 flags->options.position_sigma_m, flags->options.position_noise_m);
      fmt::print("imu meas.           {}\nstates              {}\nsegments            {}\ndegree              {}\n",
                 e.imu_measurements, e.states, e.segments, e.degree);
      fmt::print("solver iterations   {}{}\nseconds             {:.3f}\n", e.iterations,
                 e.converged ? "" : "  (did not converge)", e.seconds);
      fmt::print("mean measured collective rotor speed {:.1f} rpm\n", e.mean_measured_rpm);
      PrintErrors("collective error", e.estimate);
      PrintErrors("baseline: flatness of FD p", e.flatness);
      PrintErrors("baseline: accelerometer", e.accelerometer);
      PrintErrors("oracle: true acceleration", e.model_floor);
      fmt::print("position RMSE       {:.4f} m\nvelocity RMSE       {:.4f} m/s\n", e.position_rmse_m,
                 e.velocity_rmse_mps);
      if (!e.converged) fmt::print(stderr, "cheval: warning: the solver did not converge: {}\n", e.solver_report);
      if (!flags->json.empty()) WriteOutput(flags->json, estim::ThrustEstimateJson(e));
    };
  });
}

}  // namespace cheval::cli

// Measured figures of docs/estimator.md (a plain program: it prints tables, it does not assert).
//   quadrotor_estimate [VEHICLE_JSON] [--seeds N] [--scaling]
// 1. Every scenario x seeds 1..N (default 3; --first-seed K: K..N): per-motor mean rotor-speed error (rpm, %), pose and
//    velocity RMSE, states, iterations, seconds (one core).
// 2. --scaling: figure-eight flights of 10 s .. 300 s at the default segment length: seconds per state.
// Options (defaults: QuadrotorEstimateOptions): --duration S, --degree N, --segment S, --order M and
// --sigma-u σ (rotor smoothness prior; the pilot's with the adaptive prior), --fixed-prior (σ_u
// everywhere, no empirical Bayes), --floor σ and --pilot-iterations K (adaptive prior),
// --no-thrust-prior (the collective's random-walk rotor prior instead of the thrust-acceleration one),
// --sigma-p/-v/-w/-r σ (collocation), --trust-radius R, --window S (initialisation), --only SCENARIO,
// --first-seed K (seeds K..N), --thrust-rounds K, --thrust-order M, --motion-prior (variants of the thrust prior),
// --max-iterations K, --ftol / --gtol / --ptol X (Ceres' tolerances),
// --full-report (Ceres' report of the final solve, with stage times), --dump PREFIX (writes
// PREFIX_<scenario>_<seed>.txt: t, estimated rotor 0..3, true rotor 0..3,
// estimated and true quaternion w x y z).
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "cheval/estim/quadrotor_estimator.h"
#include "cheval/estim/quadrotor_scoring.h"
#include "cheval/estim/vehicle.h"
#include "cheval/sim/quadrotor.h"

using namespace cheval;

namespace {

struct Row {
  estim::QuadrotorEstimate estimate;
  estim::QuadrotorErrors errors;
};

Row Run(const estim::Vehicle& vehicle, sim::QuadrotorScenario scenario, uint64_t seed, double duration,
        const estim::QuadrotorEstimateOptions& options, const std::string& dump = "") {
  sim::QuadrotorSimOptions so;
  so.scenario = scenario;
  so.seed = seed;
  so.duration_s = duration;
  const estim::QuadrotorData data = sim::SimulateQuadrotor(vehicle, so);
  std::vector<double> times;
  for (const auto& t : data.truth) times.push_back(t.t);
  Row row;
  row.estimate = estim::EstimateQuadrotor(data.vehicle, data.landmarks, data.pixels, data.initial, options, times);
  row.errors = estim::CompareWithTruth(row.estimate, data.truth);
  if (!dump.empty()) {  // t, estimated rotor 0..3, true rotor 0..3 (rad/s) at the truth times
    std::FILE* f = std::fopen((dump + "_" + std::string(sim::ToString(scenario)) + "_" + std::to_string(seed) + ".txt").c_str(), "w");
    for (size_t i = 0; i < row.estimate.samples.size() && i < data.truth.size(); ++i) {
      const auto& e = row.estimate.samples[i];
      const auto& g = data.truth[i];
      const Eigen::Quaterniond qe(e.R);
      std::fprintf(f, "%.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.3f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", e.t,
                   e.rotor[0], e.rotor[1], e.rotor[2], e.rotor[3], g.rotor[0], g.rotor[1], g.rotor[2], g.rotor[3],
                   qe.w(), qe.x(), qe.y(), qe.z(), g.q.w(), g.q.x(), g.q.y(), g.q.z());
    }
    std::fclose(f);
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  std::string vehicle_path = CHEVAL_DEFAULT_VEHICLE;
  int seeds = 3;
  int first_seed = 1;
  bool scaling = false;
  double duration = 10.0;
  std::string only, dump;
  bool full_report = false;
  estim::QuadrotorEstimateOptions options;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seeds") && i + 1 < argc) seeds = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--scaling")) scaling = true;
    else if (!std::strcmp(argv[i], "--duration") && i + 1 < argc) duration = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--degree") && i + 1 < argc) options.degree = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--segment") && i + 1 < argc) options.segment_s = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--order") && i + 1 < argc) options.rotor_prior_order = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--sigma-u") && i + 1 < argc) options.sigma_rotor_rate = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--sigma-v") && i + 1 < argc) options.sigma_acceleration = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--sigma-w") && i + 1 < argc) options.sigma_angular_acceleration = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--sigma-p") && i + 1 < argc) options.sigma_position_rate = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--sigma-r") && i + 1 < argc) options.sigma_rotation_rate = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--fixed-prior")) options.adaptive_rotor_prior = false;
    else if (!std::strcmp(argv[i], "--floor") && i + 1 < argc) options.adaptive_rotor_prior_floor = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--pilot-iterations") && i + 1 < argc) options.pilot_iterations = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-thrust-prior")) options.thrust_prior = false;
    else if (!std::strcmp(argv[i], "--thrust-rounds") && i + 1 < argc) options.thrust_prior_rounds = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--thrust-order") && i + 1 < argc) options.thrust_prior_order = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--motion-prior")) options.motion_prior = true;
    else if (!std::strcmp(argv[i], "--max-iterations") && i + 1 < argc) options.max_iterations = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--ftol") && i + 1 < argc) options.function_tolerance = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--gtol") && i + 1 < argc) options.gradient_tolerance = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--ptol") && i + 1 < argc) options.parameter_tolerance = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--first-seed") && i + 1 < argc) first_seed = std::stoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--full-report")) full_report = true;
    else if (!std::strcmp(argv[i], "--trust-radius") && i + 1 < argc) options.initial_trust_region_radius = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--window") && i + 1 < argc) options.initial_window_s = std::stod(argv[++i]);
    else if (!std::strcmp(argv[i], "--only") && i + 1 < argc) only = argv[++i];
    else if (!std::strcmp(argv[i], "--dump") && i + 1 < argc) dump = argv[++i];
    else vehicle_path = argv[i];
  }
  const estim::Vehicle vehicle = estim::ReadVehicle(vehicle_path);
  if (!scaling) {
    std::printf("%-11s %4s %6s %4s %7s | %-31s | %-27s | %8s %8s %8s\n", "scenario", "seed", "states", "it", "sec",
                "rotor error rpm (motor 0..3)", "rotor error % (motor 0..3)", "pos m", "rot deg", "vel m/s");
    double worst = 0;
    for (sim::QuadrotorScenario scenario : sim::AllQuadrotorScenarios()) {
      if (!only.empty() && sim::ToString(scenario) != only) continue;
      for (int seed = first_seed; seed <= seeds; ++seed) {
        const Row r = Run(vehicle, scenario, seed, duration, options, dump);
        const auto& e = r.errors;
        std::printf("%-11s %4d %6d %4d %7.3f | %7.2f %7.2f %7.2f %7.2f | %6.3f %6.3f %6.3f %6.3f | %8.4f %8.3f %8.4f%s\n",
                    std::string(sim::ToString(scenario)).c_str(), seed, r.estimate.states, r.estimate.iterations,
                    r.estimate.seconds, e.rotor_error_rpm[0], e.rotor_error_rpm[1], e.rotor_error_rpm[2],
                    e.rotor_error_rpm[3], e.rotor_error_percent[0], e.rotor_error_percent[1], e.rotor_error_percent[2],
                    e.rotor_error_percent[3], e.position_rmse_m, e.rotation_rmse_deg, e.velocity_rmse_mps,
                    r.estimate.converged ? "" : "  (not converged)");
        worst = std::max(worst, e.rotor_error_percent.maxCoeff());
        if (full_report) std::printf("%s\n", r.estimate.solver_full_report.c_str());
      }
    }
    std::printf("worst per-motor mean rotor-speed error: %.3f %%\n", worst);
  } else {
    std::printf("%9s %7s %9s %4s %9s %12s\n", "flight s", "states", "segments", "it", "seconds", "ms / state");
    for (double d : {10.0, 30.0, 60.0, 120.0, 300.0}) {
      const Row r = Run(vehicle, sim::QuadrotorScenario::kFigureEight, 1, d, options);
      std::printf("%9.0f %7d %9d %4d %9.3f %12.3f   rotor error max %.3f %%\n", d, r.estimate.states,
                  r.estimate.segments, r.estimate.iterations, r.estimate.seconds,
                  1e3 * r.estimate.seconds / r.estimate.states, r.errors.rotor_error_percent.maxCoeff());
    }
  }
  return 0;
}

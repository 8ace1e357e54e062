// Measured figures of docs/estimator.md (a plain program: it prints tables, it does not assert).
//   quadrotor_estimate [VEHICLE_JSON] [--seeds N] [--first-seed K] [--only SCENARIO] [--duration S]
//                      [--degree N] [--segment S] [--scaling]
// 1. Every scenario (or --only one) x seeds K..N (default 1..3): per-motor mean rotor-speed error
//    (rpm, %), pose and velocity RMSE, states, iterations, seconds (one core); the worst motor.
// 2. --scaling: figure-eight flights of 10 s .. 300 s: seconds per state.
// --duration: flight length (default 10 s); --degree, --segment: QuadrotorEstimateOptions' fields
// (default: the struct's). VEHICLE_JSON defaults to the shipped vehicle file.
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "cheval/estim/quadrotor_data.h"
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
        const estim::QuadrotorEstimateOptions& options) {
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
  return row;
}

// The command line (see the top of the file); exits with a message on anything else.
struct Arguments {
  std::string vehicle_path = CHEVAL_DEFAULT_VEHICLE;
  int seeds = 3, first_seed = 1;
  bool scaling = false;
  double duration = 10.0;
  std::string only;
  estim::QuadrotorEstimateOptions options;
};

[[noreturn]] void Usage(const std::string& problem) {
  std::fprintf(stderr,
               "quadrotor_estimate: %s\nusage: quadrotor_estimate [VEHICLE_JSON] [--seeds N] [--first-seed K] "
               "[--only SCENARIO] [--duration S] [--degree N] [--segment S] [--scaling]\n",
               problem.c_str());
  std::exit(2);
}

Arguments Parse(int argc, char** argv) {
  Arguments a;
  const std::map<std::string, std::function<void(const std::string&)>> with_value = {
      {"--seeds", [&](const std::string& v) { a.seeds = std::stoi(v); }},
      {"--first-seed", [&](const std::string& v) { a.first_seed = std::stoi(v); }},
      {"--only", [&](const std::string& v) { a.only = v; }},
      {"--duration", [&](const std::string& v) { a.duration = std::stod(v); }},
      {"--degree", [&](const std::string& v) { a.options.degree = std::stoi(v); }},
      {"--segment", [&](const std::string& v) { a.options.segment_s = std::stod(v); }},
  };
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--scaling") {
      a.scaling = true;
    } else if (const auto it = with_value.find(arg); it != with_value.end()) {
      if (i + 1 >= argc) Usage(arg + " needs a value");
      try {
        it->second(argv[++i]);
      } catch (const std::exception&) {
        Usage("bad value '" + std::string(argv[i]) + "' for " + arg);
      }
    } else if (arg.rfind("--", 0) == 0) {
      Usage("unknown option " + arg);
    } else {
      a.vehicle_path = arg;
    }
  }
  if (!a.only.empty() && !sim::QuadrotorScenarioFromString(a.only)) Usage("unknown scenario " + a.only);
  return a;
}

}  // namespace

int main(int argc, char** argv) {
  const Arguments args = Parse(argc, argv);
  const estim::QuadrotorEstimateOptions& options = args.options;
  const int seeds = args.seeds, first_seed = args.first_seed;
  const double duration = args.duration;
  const std::string& only = args.only;
  const estim::Vehicle vehicle = estim::ReadVehicle(args.vehicle_path);
  if (!args.scaling) {
    std::printf("%-11s %4s %6s %4s %7s | %-31s | %-27s | %8s %8s %8s\n", "scenario", "seed", "states", "it", "sec",
                "rotor error rpm (motor 0..3)", "rotor error % (motor 0..3)", "pos m", "rot deg", "vel m/s");
    double worst = 0;
    for (sim::QuadrotorScenario scenario : sim::AllQuadrotorScenarios()) {
      if (!only.empty() && sim::ToString(scenario) != only) continue;
      for (int seed = first_seed; seed <= seeds; ++seed) {
        const Row r = Run(vehicle, scenario, seed, duration, options);
        const auto& e = r.errors;
        std::printf("%-11s %4d %6d %4d %7.3f | %7.2f %7.2f %7.2f %7.2f | %6.3f %6.3f %6.3f %6.3f | %8.4f %8.3f %8.4f%s\n",
                    std::string(sim::ToString(scenario)).c_str(), seed, r.estimate.states, r.estimate.iterations,
                    r.estimate.seconds, e.rotor_error_rpm[0], e.rotor_error_rpm[1], e.rotor_error_rpm[2],
                    e.rotor_error_rpm[3], e.rotor_error_percent[0], e.rotor_error_percent[1], e.rotor_error_percent[2],
                    e.rotor_error_percent[3], e.position_rmse_m, e.rotation_rmse_deg, e.velocity_rmse_mps,
                    r.estimate.converged ? "" : "  (not converged)");
        worst = std::max(worst, e.rotor_error_percent.maxCoeff());
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

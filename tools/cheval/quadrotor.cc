// `cheval sim quadrotor` and `cheval estimate quadrotor`: the simulated quadrotor flight and the
// pseudo-spectral estimate of its states and rotor speeds from the camera (docs/estimator.md).
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <vector>

#include "cheval/common/error.h"
#include "cheval/estim/quadrotor_data.h"
#include "cheval/estim/quadrotor_estimator.h"
#include "cheval/estim/quadrotor_scoring.h"
#include "cheval/sim/quadrotor.h"
#include "common.h"
#include "progress.h"

namespace cheval::cli {
namespace {

// The default vehicle file: the installed one (PREFIX/share/cheval/vehicles beside PREFIX/bin/cheval),
// else the source tree's (running from a build folder).
std::string DefaultVehicle() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path installed =
        exe.parent_path().parent_path() / "share" / "cheval" / "vehicles" / "flightgoggles.json";
    if (std::filesystem::is_regular_file(installed, ec)) return installed.string();
  }
  return CHEVAL_DEFAULT_VEHICLE;
}

struct QuadrotorFlags {
  std::string scenario;
  uint64_t seed = 1;
  double duration_s = 10.0;
  std::string vehicle = DefaultVehicle();
  std::string data;
  std::string output;
  std::string json;
  std::string states_output;  // estimate -o: the estimated states, truth.csv's layout
  estim::QuadrotorEstimateOptions options;
};

sim::QuadrotorSimOptions SimOptions(const QuadrotorFlags& flags) {
  const auto scenario = sim::QuadrotorScenarioFromString(flags.scenario);
  if (!scenario) {
    throw UsageError(fmt::format("--scenario: unknown scenario '{}' (expected hover, line, circle, figure8, lissajous "
                                 "or aggressive)",
                                 flags.scenario));
  }
  sim::QuadrotorSimOptions options;
  options.scenario = *scenario;
  options.seed = flags.seed;
  options.duration_s = flags.duration_s;
  return options;
}

void AddSimFlags(CLI::App* command, QuadrotorFlags* flags) {
  command->add_option("--scenario", flags->scenario, "hover|line|circle|figure8|lissajous|aggressive");
  command->add_option("--seed", flags->seed, "Random seed (landmarks, pixel noise, front-end noise)")->capture_default_str();
  command->add_option("--duration", flags->duration_s, "Flight duration (s)")->capture_default_str();
  command->add_option("--vehicle", flags->vehicle, "Vehicle + camera JSON file")->capture_default_str();
}

}  // namespace

void RegisterSimQuadrotor(CLI::App& app, Action* action) {
  CLI::App* sim_command = app.get_subcommand("sim");
  auto flags = std::make_shared<QuadrotorFlags>();
  CLI::App* quad = sim_command->add_subcommand(
      "quadrotor", "Quadrotor flight with motor lag, camera measurements of known landmarks and front-end poses");
  AddSimFlags(quad, flags.get());
  quad->get_option("--scenario")->required();
  quad->add_option("-o,--output", flags->output, "Data folder to write")->required();
  quad->callback([flags, action] {
    *action = [flags] {
      // A data folder from an earlier run is replaced whole (estim::WriteQuadrotorData): the vehicle
      // file must not be in it.
      RefuseSharedPaths({flags->vehicle}, {{"-o", flags->output, OutputKind::kReplacedFolder}});
      const estim::Vehicle vehicle = estim::ReadVehicle(flags->vehicle);
      const estim::QuadrotorData data = sim::SimulateQuadrotor(vehicle, SimOptions(*flags));
      estim::WriteQuadrotorData(data, flags->output);
      if (!Quiet()) fmt::print(stderr, "wrote {} ({} s, seed {}): {} frames, {} pixel measurements, {} landmarks, {} truth samples to {}\n",
                 flags->scenario, flags->duration_s, flags->seed, data.initial.size(), data.pixels.size(),
                 data.landmarks.size(), data.truth.size(), flags->output);
    };
  });
}

void RegisterEstimate(CLI::App& app, Action* action) {
  CLI::App* estimate = app.add_subcommand("estimate", "Pseudo-spectral continuous-time state and dynamics estimation");
  estimate->require_subcommand(1);
  auto flags = std::make_shared<QuadrotorFlags>();
  CLI::App* quad = estimate->add_subcommand(
      "quadrotor", "States and rotor speeds of a quadrotor from camera measurements and its dynamics");
  AddSimFlags(quad, flags.get());
  quad->add_option("--data", flags->data,
                   "Data folder (as written by `cheval sim quadrotor`) instead of --scenario; its vehicle.json is used "
                   "unless --vehicle is given");
  quad->add_option("--degree", flags->options.degree, "Polynomial degree per segment")->capture_default_str();
  quad->add_option("--segment", flags->options.segment_s, "Segment length (s)")->capture_default_str();
  quad->add_option("--json", flags->json, "Write the result as JSON");
  quad->add_option("-o,--output", flags->states_output,
                   "Write the estimated states and rotor speeds as CSV (truth.csv's columns), at the truth's times, "
                   "else every 10 ms");
  quad->callback([flags, action, quad] {
    const bool has_scenario = quad->get_option("--scenario")->count() > 0;
    const bool has_data = quad->get_option("--data")->count() > 0;
    const bool has_vehicle = quad->get_option("--vehicle")->count() > 0;
    *action = [flags, has_scenario, has_data, has_vehicle] {
      if (has_scenario == has_data) throw UsageError("give exactly one of --scenario NAME or --data DIR");
      std::vector<std::string> inputs{flags->vehicle};
      if (has_data) {
        for (const std::string_view name : estim::kQuadrotorDataFiles) {
          inputs.push_back((std::filesystem::path(flags->data) / name).string());
        }
      }
      RefuseSharedPaths(inputs, {{"-o", flags->states_output}, {"--json", flags->json}});
      estim::QuadrotorData data;
      if (has_data) {
        data = estim::ReadQuadrotorData(flags->data);
        // An explicit --vehicle replaces the folder's vehicle.json (e.g. to study a wrong model).
        if (has_vehicle) data.vehicle = estim::ReadVehicle(flags->vehicle);
      } else {
        data = sim::SimulateQuadrotor(estim::ReadVehicle(flags->vehicle), SimOptions(*flags));
      }
      const std::vector<double> times = estim::ReportTimes(data);  // the truth's, else every 10 ms
      estim::QuadrotorEstimateOptions options = flags->options;
      options.progress = Progress().Fn();  // on a terminal only
      const estim::QuadrotorEstimate e =
          estim::EstimateQuadrotor(data.vehicle, data.landmarks, data.pixels, data.initial, options, times);
      Progress().Clear();  // the iteration count has no end of its own
      fmt::print("states              {}\nsegments            {}\ndegree              {}\n", e.states, e.segments,
                 e.degree);
      fmt::print("solver iterations   {}{}\nseconds             {:.3f}\n", e.iterations,
                 e.converged ? "" : "  (did not converge)", e.seconds);
      std::optional<estim::QuadrotorErrors> errors;
      if (!data.truth.empty()) {
        errors = estim::CompareWithTruth(e, data.truth);
        const Eigen::Vector4d& rpm = errors->rotor_error_rpm;
        const Eigen::Vector4d& percent = errors->rotor_error_percent;
        fmt::print("rotor error rpm     {:.2f} {:.2f} {:.2f} {:.2f}\n", rpm[0], rpm[1], rpm[2], rpm[3]);
        fmt::print("rotor error %       {:.3f} {:.3f} {:.3f} {:.3f}\n", percent[0], percent[1], percent[2], percent[3]);
        fmt::print("position RMSE       {:.4f} m\nrotation RMSE       {:.3f} deg\nvelocity RMSE       {:.4f} m/s\n",
                   errors->position_rmse_m, errors->rotation_rmse_deg, errors->velocity_rmse_mps);
      } else {
        fmt::print("(no truth.csv: no errors)\n");
      }
      if (!e.converged) fmt::print(stderr, "cheval: warning: the solver did not converge: {}\n", e.solver_report);
      // Both outputs are formatted before either is written.
      const std::string json = estim::QuadrotorEstimateJson(e, errors ? &*errors : nullptr);
      const std::string states = flags->states_output.empty() ? "" : estim::QuadrotorStatesCsv(estim::EstimatedStates(e));
      std::vector<OutputFile> files;
      if (!flags->states_output.empty()) files.push_back({flags->states_output, states});
      if (!flags->json.empty()) files.push_back({flags->json, json});
      WriteOutputs(files);
    };
  });
}

}  // namespace cheval::cli

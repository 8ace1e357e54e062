// `cheval sim motion`: synthetic trajectories with exact derivatives (truth) and their measured copy
// (noise, jittered stamps, dropouts, gaps). See docs/sim.md.
#include <fmt/format.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "cheval/common/error.h"
#include "cheval/common/memory.h"
#include "cheval/sim/motion.h"
#include "common.h"
#include "progress.h"

namespace cheval::cli {
namespace {

struct SimMotionFlags {
  std::string kind = "drone";
  uint64_t seed = 1;
  double duration_s = 0.0;  // used only when given; else the kind's default
  double rate_hz = 0.0;     // used only when given; else the kind's default
  sim::MeasurementOptions measurement;
  std::string output;
  std::string truth_output;
  std::vector<std::string> estimate_outputs;  // --estimate, repeatable: one simulated estimator each
  sim::EstimatorSimOptions estimator;
  std::vector<double> estimate_drifts;  // --estimate-drift: one value for all, or one per estimate
};

}  // namespace

void RegisterSim(CLI::App& app, Action* action) {
  CLI::App* sim = app.add_subcommand("sim", "Generate synthetic data");
  sim->require_subcommand(1);
  auto flags = std::make_shared<SimMotionFlags>();
  CLI::App* motion = sim->add_subcommand(
      "motion", "Synthetic motion with exact derivatives (truth) and a measured copy with noise, jitter and gaps");
  motion->add_option("--kind", flags->kind, "Kind of motion")
      ->check(CLI::IsMember({"car", "legged", "drone", "handheld"}))
      ->capture_default_str();
  motion->add_option("--seed", flags->seed, "Random seed (shape parameters and measurement effects)")
      ->capture_default_str();
  CLI::Option* duration = motion->add_option(
      "--duration", flags->duration_s, "Duration (s); default per kind: car 100, legged 10, drone 60, handheld 30");
  CLI::Option* rate = motion->add_option(
      "--rate", flags->rate_hz, "Sample rate (Hz); default per kind: car 50, legged 200, drone 200, handheld 100");
  motion->add_option("--noise", flags->measurement.noise_m, "Position noise sigma (m) of the measured file")
      ->capture_default_str();
  motion
      ->add_option("--rotation-noise", flags->measurement.rotation_noise_rad,
                   "Orientation noise sigma (rad) of the measured file: R Exp(n), n ~ N(0, sigma^2 I)")
      ->capture_default_str();
  motion->add_option("--jitter", flags->measurement.jitter_s, "Stamp jitter sigma (s) of the measured file")
      ->capture_default_str();
  motion
      ->add_option("--dropout", flags->measurement.dropout_probability,
                   "Probability of dropping each measured sample, in [0, 1)")
      ->capture_default_str();
  motion->add_option("--gap-count", flags->measurement.gap_count, "Number of longer gaps in the measured file")
      ->capture_default_str();
  motion->add_option("--gap-seconds", flags->measurement.gap_s, "Length of each gap (s)")->capture_default_str();
  motion->add_option("-o,--output", flags->output, "Measured trajectory (TUM)")->required();
  motion->add_option("--truth", flags->truth_output, "Exact trajectory on the nominal grid (TUM + velocity)");
  motion->add_option("--estimate", flags->estimate_outputs,
                     "A simulated estimator's output (TUM + velocity, drifting like an odometry); repeat for several");
  motion->add_option("--estimate-rate", flags->estimator.rate_hz, "Rate of the estimates (Hz)")->capture_default_str();
  motion
      ->add_option("--estimate-drift", flags->estimate_drifts,
                   "Random walk of the estimates' velocity error (m/s per sqrt(s)): one value, or one per --estimate")
      ->default_str(fmt::format("{}", flags->estimator.velocity_random_walk));
  motion
      ->add_option("--estimate-rotation-drift", flags->estimator.rotation_random_walk_rad,
                   "Random walk of the estimates' orientation error (rad per sqrt(s))")
      ->capture_default_str();
  motion->callback([flags, action, duration, rate] {
    const bool duration_given = duration->count() > 0, rate_given = rate->count() > 0;
    *action = [flags, duration_given, rate_given] {
      const size_t n_estimates = flags->estimate_outputs.size();
      if (flags->estimate_drifts.size() > 1 && flags->estimate_drifts.size() != n_estimates) {
        throw UsageError(fmt::format("--estimate-drift: give one value or one per --estimate ({}), got {}",
                                     n_estimates, flags->estimate_drifts.size()));
      }
      std::vector<OutputPath> paths{{"-o", flags->output}, {"--truth", flags->truth_output}};
      for (const std::string& path : flags->estimate_outputs) paths.push_back({"--estimate", path});
      RefuseSharedPaths({}, paths);
      sim::MotionOptions options;
      options.kind = *sim::MotionKindFromString(flags->kind);
      options.seed = flags->seed;
      if (duration_given) options.duration_s = flags->duration_s;
      if (rate_given) options.rate_hz = flags->rate_hz;
      const sim::MotionModel model(options);
      // The samples and their text, checked before they are generated (measured: about 330 bytes a
      // measured sample with the truth it is drawn from, 270 more when the truth is written, 300 a
      // sample of each estimate).
      const sim::MotionOptions& resolved = model.options();
      const double samples = std::floor(*resolved.duration_s * *resolved.rate_hz) + 1.0;
      const double estimate_samples = std::floor(*resolved.duration_s * flags->estimator.rate_hz) + 1.0;
      const double measured_bytes = samples * (flags->truth_output.empty() ? 350.0 : 650.0);
      const double estimate_bytes = static_cast<double>(flags->estimate_outputs.size()) * estimate_samples * 320.0;
      const bool estimates_dominate = estimate_bytes > measured_bytes;  // the flag to name
      CheckMemory({estimates_dominate ? "EstimatorSimOptions" : "MotionOptions", "rate_hz",
                   measured_bytes + estimate_bytes,
                   fmt::format("{:.4g} samples over {} s{}", samples, *resolved.duration_s,
                               flags->estimate_outputs.empty()
                                   ? ""
                                   : fmt::format(" and {} estimate(s) of {:.4g} samples", flags->estimate_outputs.size(),
                                                 estimate_samples)),
                   MemoryCost::kOption});
      const traj::Trajectory measured = sim::Measure(model, flags->measurement);
      const traj::Trajectory truth = sim::GenerateMotion(model);
      // Everything is formatted before anything is written.
      std::vector<std::pair<std::string, std::string>> outputs;  // (path, text), written all at once or none
      outputs.emplace_back(flags->output, traj::FormatTrajectory(measured.View(), traj::Format::kTum));
      if (!flags->truth_output.empty()) {
        outputs.emplace_back(flags->truth_output, traj::FormatTrajectory(truth.View(), traj::Format::kTumV));
      }
      for (size_t k = 0; k < n_estimates; ++k) {
        sim::EstimatorSimOptions estimator = flags->estimator;
        estimator.stream = k;
        if (!flags->estimate_drifts.empty()) {
          estimator.velocity_random_walk = flags->estimate_drifts[flags->estimate_drifts.size() == 1 ? 0 : k];
        }
        const traj::Trajectory estimate = sim::SimulateEstimate(model, estimator);
        outputs.emplace_back(flags->estimate_outputs[k], traj::FormatTrajectory(estimate.View(), traj::Format::kTumV));
      }
      std::vector<OutputFile> files;
      for (const auto& [path, text] : outputs) files.push_back({path, text});
      WriteOutputs(files);
      const sim::MotionOptions& used = model.options();
      if (!Quiet()) fmt::print(stderr,
                 "wrote {} measured poses ({}, {} s at {} Hz, seed {}; noise {} m, jitter {} s, {} removed by dropouts "
                 "and gaps) to {}{}\n",
                 measured.size(), sim::ToString(used.kind), *used.duration_s, *used.rate_hz, used.seed,
                 flags->measurement.noise_m, flags->measurement.jitter_s, truth.size() - measured.size(), flags->output,
                 flags->truth_output.empty()
                     ? ""
                     : fmt::format(" and {} exact poses to {}", truth.size(), flags->truth_output));
      if (!Quiet() && n_estimates > 0) {
        fmt::print(stderr, "wrote {} simulated estimate{} at {} Hz\n", n_estimates, n_estimates > 1 ? "s" : "",
                   flags->estimator.rate_hz);
      }
    };
  });
}

}  // namespace cheval::cli

// `cheval sim motion`: synthetic trajectories with exact derivatives (truth) and their measured copy
// (noise, jittered stamps, dropouts, gaps). See docs/sim.md.
#include <fmt/format.h>

#include <filesystem>

#include "cheval/common/error.h"
#include "cheval/sim/motion.h"
#include "common.h"

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
  motion->callback([flags, action, duration, rate] {
    const bool duration_given = duration->count() > 0, rate_given = rate->count() > 0;
    *action = [flags, duration_given, rate_given] {
      sim::MotionOptions options;
      options.kind = *sim::MotionKindFromString(flags->kind);
      options.seed = flags->seed;
      if (duration_given) options.duration_s = flags->duration_s;
      if (rate_given) options.rate_hz = flags->rate_hz;
      const sim::MotionModel model(options);
      const traj::Trajectory measured = sim::Measure(model, flags->measurement);
      const traj::Trajectory truth = sim::GenerateMotion(model);
      // Everything is formatted before anything is written; if the second file cannot be written the
      // first is removed again, so a failure leaves neither behind.
      const std::string measured_text = traj::FormatTrajectory(measured.View(), traj::Format::kTum);
      const std::string truth_text =
          flags->truth_output.empty() ? "" : traj::FormatTrajectory(truth.View(), traj::Format::kTumV);
      traj::WriteFileAtomically(flags->output, measured_text);
      if (!flags->truth_output.empty()) {
        try {
          traj::WriteFileAtomically(flags->truth_output, truth_text);
        } catch (...) {
          std::error_code ignored;
          std::filesystem::remove(flags->output, ignored);
          throw;
        }
      }
      const sim::MotionOptions& used = model.options();
      fmt::print(stderr,
                 "wrote {} measured poses ({}, {} s at {} Hz, seed {}; noise {} m, jitter {} s, {} removed by dropouts "
                 "and gaps) to {}{}\n",
                 measured.size(), sim::ToString(used.kind), *used.duration_s, *used.rate_hz, used.seed,
                 flags->measurement.noise_m, flags->measurement.jitter_s, truth.size() - measured.size(), flags->output,
                 flags->truth_output.empty()
                     ? ""
                     : fmt::format(" and {} exact poses to {}", truth.size(), flags->truth_output));
    };
  });
}

}  // namespace cheval::cli

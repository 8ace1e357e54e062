// `cheval sim motion`: synthetic trajectories with exact derivatives (truth) and noisy measurements.
#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/sim/motion.h"
#include "common.h"

namespace cheval::cli {
namespace {

struct SimMotionFlags {
  std::string kind = "drone";
  uint64_t seed = 1;
  double noise_m = 0.0;
  double duration_s = 60.0;
  double rate_hz = 200.0;
  std::string output;
  std::string truth_output;
};

}  // namespace

void RegisterSim(CLI::App& app, Action* action) {
  CLI::App* sim = app.add_subcommand("sim", "Generate synthetic data");
  sim->require_subcommand(1);
  auto flags = std::make_shared<SimMotionFlags>();
  CLI::App* motion = sim->add_subcommand("motion", "Synthetic motion with exact derivatives and position noise");
  motion->add_option("--kind", flags->kind, "Kind of motion")->check(CLI::IsMember({"drone"}))->capture_default_str();
  motion->add_option("--seed", flags->seed, "Random seed")->capture_default_str();
  motion->add_option("--noise", flags->noise_m, "Position noise sigma (m) of the measured file")->capture_default_str();
  motion->add_option("--duration", flags->duration_s, "Duration (s)")->capture_default_str();
  motion->add_option("--rate", flags->rate_hz, "Sample rate (Hz)")->capture_default_str();
  motion->add_option("-o,--output", flags->output, "Measured trajectory (TUM, noisy positions)")->required();
  motion->add_option("--truth", flags->truth_output, "Exact trajectory (TUM + velocity)");
  motion->callback([flags, action] {
    *action = [flags] {
      sim::MotionOptions options;
      options.kind = *sim::MotionKindFromString(flags->kind);
      options.seed = flags->seed;
      options.duration_s = flags->duration_s;
      options.rate_hz = flags->rate_hz;
      const traj::Trajectory truth = sim::GenerateMotion(options);
      const traj::Trajectory measured = sim::AddPositionNoise(truth.View(), flags->noise_m, flags->seed);
      const std::string measured_text = traj::FormatTrajectory(measured.View(), traj::Format::kTum);
      const std::string truth_text =
          flags->truth_output.empty() ? "" : traj::FormatTrajectory(truth.View(), traj::Format::kTumV);
      traj::WriteFileAtomically(flags->output, measured_text);
      if (!flags->truth_output.empty()) traj::WriteFileAtomically(flags->truth_output, truth_text);
      fmt::print(stderr, "wrote {} poses ({} s at {} Hz, noise {} m) to {}{}\n", measured.size(), flags->duration_s,
                 flags->rate_hz, flags->noise_m, flags->output,
                 flags->truth_output.empty() ? "" : " and the truth to " + flags->truth_output);
    };
  });
}

}  // namespace cheval::cli

// `cheval velocity IN [-o OUT]`: world-frame linear velocity from positions (C-ASE ground truth).
// Flags -> eval::VelocityOptions, then eval::EstimateVelocity, eval::VelocityTrajectory and
// eval::VelocityJson (docs/velocity.md).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/eval/velocity.h"
#include "common.h"
#include "progress.h"

namespace cheval::cli {
namespace {

struct VelocityFlags {
  std::string input;
  std::string output;
  eval::VelocityOptions options;  // angular bound; the rest from the texts below
  std::string method{eval::ToString(options.method)};
  std::string degree = eval::DegreeName(options.curve);
  std::optional<double> window_s;  // unset: not given (a given 0 is refused by the library)
  int threads = 0;
  std::string at_path;
  std::string json_path;
  InputFlags format;
};

// The library's options from the flags: --window is the Chebyshev window, or Savitzky–Golay's in
// seconds.
eval::VelocityOptions ToOptions(const VelocityFlags& flags) {
  eval::VelocityOptions options = flags.options;
  options.method = *eval::VelocityMethodFromString(flags.method);
  const std::optional<double> window = flags.window_s;
  const bool savgol = options.method == eval::VelocityMethod::kSavitzkyGolay;
  options.curve = eval::CurveOptionsFromNames(flags.degree, savgol ? std::nullopt : window);
  if (savgol) options.savgol_window_s = window;
  options.curve.threads = flags.threads;
  options.curve.progress = Progress().Fn();  // on a terminal only (progress.h)
  return options;
}

void Run(const VelocityFlags& flags) {
  const auto start = std::chrono::steady_clock::now();
  eval::VelocityOptions options = ToOptions(flags);
  // --at another file's stamps: those the fit does not cover (an estimate that runs longer than the
  // reference, or into its gaps) are left out and said, not an error.
  options.skip_uncovered = !flags.at_path.empty();
  options.Validate();
  RefuseSharedPaths({flags.input, flags.format.kitti_times, flags.at_path},
                    {{"-o", flags.output}, {"--json", flags.json_path}});
  const traj::Trajectory trajectory = traj::ReadTrajectory(flags.input, flags.format.ToReadOptions());
  const traj::TrajectoryView view = trajectory.View();
  std::optional<std::vector<int64_t>> at;
  if (!flags.at_path.empty()) at = ReadQueryStamps(flags.at_path);
  const auto at_span = at ? std::optional<std::span<const int64_t>>(*at) : std::nullopt;
  const eval::VelocityEstimate estimate = eval::EstimateVelocity(view, options, at_span);
  if (at && !at->empty() && estimate.skipped.size() == at->size()) {
    throw ComputeError(fmt::format("--at {}: none of its {} stamps lies within {}'s fitted data (its samples, gaps "
                                   "left out)",
                                   flags.at_path, at->size(), flags.input));
  }
  std::optional<traj::Trajectory> out;  // formatted a block at a time as it is written
  if (!flags.output.empty()) out = eval::VelocityTrajectory(view, estimate, at_span);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string json = eval::VelocityJson(
      {flags.input, view.size(), options, at ? at->size() - estimate.skipped.size() : static_cast<size_t>(view.size()),
       seconds},
      estimate);
  if (!view.has_orientation() && !flags.output.empty()) {
    fmt::print(stderr, "cheval: warning: {} has no orientation; {} gets identity quaternions\n", flags.input,
               flags.output);
  }
  if (!estimate.skipped.empty()) {
    const int64_t first = (*at)[estimate.skipped.front()];  // as the file gives it, to the nanosecond
    const int64_t whole = first / 1'000'000'000, nanoseconds = std::abs(first % 1'000'000'000);
    fmt::print(stderr, "cheval: note: {}: {} of its {} stamps lie outside {}'s fitted data (before its first sample, "
               "after its last, or in a gap) and were left out; the first is {}{}.{:09d} s\n",
               flags.at_path, estimate.skipped.size(), at->size(), flags.input, first < 0 && whole == 0 ? "-" : "",
               whole, nanoseconds);
  }
  std::vector<OutputFile> files;
  if (out) {
    files.push_back({flags.output, [&out](const TextSink& sink) {
                       traj::FormatTrajectory(out->View(), traj::Format::kTumV, sink);
                     }});
  }
  if (!flags.json_path.empty()) files.push_back({flags.json_path, json});
  WriteOutputs(files);
  if (!estimate.curve) {
    fmt::print("{}: {} poses, method {}, {:.3f} s\n", flags.input, view.size(), flags.method, seconds);
    return;
  }
  const cheb::Curve& curve = *estimate.curve;
  if (estimate.rounded_stamps) {
    fmt::print(stderr, "cheval: note: {}: the stamps are a uniform {:.6g} Hz rounded to {:g} s; fitted at the uniform "
               "instants (docs/velocity.md, \"Rounded stamps\")\n",
               flags.input, estimate.rounded_stamps->rate_hz(), estimate.rounded_stamps->resolution_s());
  }
  if (const std::string warning = eval::UnresolvedWarning(curve); !warning.empty()) {
    fmt::print(stderr, "cheval: warning: {}: {}\n", flags.input, warning);
  }
  if (!curve.outlier_times().empty() || !curve.jump_times().empty() || !curve.step_times().empty()) {
    fmt::print(stderr, "cheval: note: {}: {} sample(s) left out as outliers, {} step(s) of the positions taken out, "
               "split at {} jump(s) (--json lists the windows; docs/velocity.md, \"Jumps and glitches\")\n",
               flags.input, curve.outlier_times().size(), curve.step_times().size(), curve.jump_times().size());
  }
  if (curve.stamp_noise_s() > 0.0) {
    fmt::print(stderr, "cheval: note: {}: the positions scatter in proportion to their rate, as stamps off by {:.3g} ms "
               "(RMS) make them; the fit takes that noise into account (docs/velocity.md, \"Stamp noise\")\n",
               flags.input, 1e3 * curve.stamp_noise_s());
  }
  std::string at_rounding, staircase;
  for (Eigen::Index c = 0; c < 3; ++c) {
    std::string* list = curve.staircase()[static_cast<size_t>(c)] ? &staircase : curve.AtRounding(c) ? &at_rounding : nullptr;
    if (list == nullptr) continue;
    *list += fmt::format("{}{} to {:.3g} mm", list->empty() ? "" : ", ", "xyz"[c], 1e3 * curve.resolution()[c]);
    if (list == &at_rounding) *list += fmt::format(": noise {:.3g} mm", 1e3 * curve.noise_sigma()[c]);
  }
  if (!at_rounding.empty()) {
    fmt::print(stderr, "cheval: note: {}: the positions are rounded ({}) and their differences read no more noise than "
               "that rounding makes, step/sqrt(12) with any noise before it: the fit takes that as their noise, and a "
               "staircase of them is not taken for motion (docs/velocity.md, \"Rounded positions\")\n",
               flags.input, at_rounding);
  }
  if (!staircase.empty()) {
    fmt::print(stderr, "cheval: note: {}: the positions are rounded ({}) and move less than a step a sample: they were "
               "placed between their steps, on a curve through the instants they pass from one step to the next "
               "(docs/velocity.md, \"Rounded positions\")\n",
               flags.input, staircase);
  }
  size_t windows = 0;
  int min_degree = curve.segments().front().windows.front().degrees.front(), max_degree = min_degree;
  for (const cheb::CurveSegment& segment : curve.segments()) {
    windows += segment.windows.size();
    for (const cheb::CurveWindow& w : segment.windows) {
      min_degree = std::min(min_degree, *std::min_element(w.degrees.begin(), w.degrees.end()));
      max_degree = std::max(max_degree, *std::max_element(w.degrees.begin(), w.degrees.end()));
    }
  }
  const std::string noisier =
      curve.noisier_samples() > 0
          ? fmt::format(" (up to {:.3g} m over {} noisier samples)", curve.noise_sigma_max().maxCoeff(), curve.noisier_samples())
          : std::string();
  fmt::print("{}: {} poses, {} windows in {} segments, degrees {}..{}, noise sigma {:.3g} m{}, residual RMSE "
             "{:.3g} m, compression {:.1f}x, {:.3f} s\n",
             flags.input, view.size(), windows, curve.segments().size(), min_degree, max_degree,
             curve.noise_sigma().mean(), noisier, curve.residual_rms().mean(),
             static_cast<double>(3 * view.size()) / static_cast<double>(curve.stored_values()), seconds);
}

}  // namespace

void RegisterVelocity(CLI::App& app, Action* action) {
  auto flags = std::make_shared<VelocityFlags>();
  CLI::App* command = app.add_subcommand(
      "velocity", "World-frame linear velocity from positions by Chebyshev fitting (or central differences, "
                  "Savitzky-Golay)");
  command->add_option("input", flags->input, "Trajectory file (positions are used)")->required();
  command->add_option("-o,--output", flags->output,
                      "Write TUM + velocity (t x y z qx qy qz qw vx vy vz [wx wy wz]), orientation as read");
  command->add_option(Flag("VelocityOptions::method"), flags->method, "Velocity method")
      ->check(CLI::IsMember({"chebyshev", "central", "savgol"}))
      ->capture_default_str();
  command->add_option(Flag("CurveOptions::degree_method"), flags->degree,
                      "chebyshev: auto = cv (5-fold cross-validation per window), chop (standardChop at the "
                      "estimated noise level) or a fixed degree")
      ->capture_default_str();
  command->add_option(Flag("CurveOptions::window_s"), flags->window_s,
                      "chebyshev: fixed window length in seconds (default: adaptive); savgol: window in seconds "
                      "(default 21 samples)");
  command->add_option(Flag("CurveOptions::threads"), flags->threads,
                      "chebyshev: threads for the fit and its evaluation (default 0: the machine's cores); the "
                      "result is the same for any number");
  command->add_option("--at", flags->at_path,
                      "Evaluate at these stamps: a file of one stamp (s) per line, or a trajectory file");
  command->add_flag(Flag("VelocityOptions::angular"), flags->options.angular,
                    "Also body angular velocity from the orientations, appended as wx wy wz (rad/s)");
  command->add_option("--json", flags->json_path, "Write what was done as JSON");
  AddInputFlags(command, &flags->format);
  command->callback([flags, action] { *action = [flags] { Run(*flags); }; });
}

}  // namespace cheval::cli

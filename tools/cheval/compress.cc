// `cheval compress IN -o MODEL.json [--tolerance M]`: the pseudo-spectral model of a trajectory's
// positions (docs/compress.md).
#include <chrono>
#include <optional>

#include <fmt/format.h>

#include <vector>

#include "cheval/cheb/compress.h"
#include "cheval/common/error.h"
#include "cheval/traj/stamp.h"
#include "common.h"
#include "progress.h"

namespace cheval::cli {
namespace {

struct CompressFlags {
  std::string input;
  std::string output;
  std::optional<double> tolerance;
  std::string json_path;
  InputFlags format;
};

}  // namespace

void RegisterCompress(CLI::App& app, Action* action) {
  auto flags = std::make_shared<CompressFlags>();
  CLI::App* command = app.add_subcommand(
      "compress",
      "Store a trajectory's positions as windowed Chebyshev polynomials (values at Chebyshev points, JSON)");
  command->add_option("input", flags->input, "Trajectory file (positions are used)")->required();
  command->add_option("-o,--output", flags->output, "Model file to write (JSON, docs/compress.md)")->required();
  command->add_option("--tolerance", flags->tolerance,
                      "Largest reconstruction error accepted at the input samples, metres (Euclidean): the smallest "
                      "model found within it is stored, or the command fails saying what can be reached");
  command->add_option("--json", flags->json_path, "Write what was done as JSON");
  AddInputFlags(command, &flags->format);
  command->callback([flags, action] {
    *action = [flags] {
      const auto start = std::chrono::steady_clock::now();
      cheb::CompressOptions options;
      options.tolerance = flags->tolerance;
      options.Validate();  // before any work
      RefuseSharedPaths({flags->input, flags->format.kitti_times}, {{"-o", flags->output}, {"--json", flags->json_path}});
      const traj::Trajectory trajectory = traj::ReadTrajectory(flags->input, flags->format.ToReadOptions());
      const traj::TrajectoryView view = trajectory.View();
      if (!view.has_stamps()) throw ComputeError("compress needs stamps; give the KITTI times with --kitti-times");
      const Eigen::MatrixXd positions = view.positions().transpose();
      options.curve.progress = Progress().Fn();  // on a terminal only
      const cheb::Compression result = cheb::Compress(view.stamps_ns(), positions, options);
      const std::string text = cheb::WriteModelJson(result.model);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::string report = cheb::CompressionJson(
          {flags->input, view.size(), view.has_orientation(), flags->output, text.size(), flags->tolerance, seconds},
          result);
      std::vector<OutputFile> files{{flags->output, text}};
      if (!flags->json_path.empty()) files.push_back({flags->json_path, report});
      WriteOutputs(files);
      size_t windows = 0;
      for (const cheb::ModelSegment& segment : result.model.segments) windows += segment.windows.size();
      fmt::print(
          "{}: {} poses -> {}: {} window{} in {} segment{}, {} numbers for {} positions: compression {:.1f}x; "
          "max error {:.3g} m, RMS {:.3g} m at the input samples{}; {:.3f} s\n",
          flags->input, view.size(), flags->output, windows, windows == 1 ? "" : "s", result.model.segments.size(),
          result.model.segments.size() == 1 ? "" : "s", result.model_numbers, result.input_numbers, result.ratio,
          result.error.max, result.error.rms, view.has_orientation() ? " (orientation is not stored)" : "", seconds);
    };
  });
}

}  // namespace cheval::cli

// `cheval compress IN -o MODEL.json [--tolerance M]`: the pseudo-spectral model of a trajectory's
// positions (docs/compress.md).
#include <chrono>
#include <optional>

#include <fmt/format.h>

#include <vector>
#include <nlohmann/json.hpp>

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

nlohmann::json Report(const CompressFlags& flags, const traj::TrajectoryView& input, const cheb::Compression& c,
                      size_t model_bytes, double seconds) {
  const cheb::TrajectoryModel& model = c.model;
  std::vector<int> degrees;
  size_t windows = 0;
  for (const cheb::ModelSegment& segment : model.segments) {
    windows += segment.windows.size();
    for (const cheb::ModelWindow& w : segment.windows) {
      for (size_t k = 0; k < w.values.size(); ++k) degrees.push_back(w.degree(k));
    }
  }
  nlohmann::json j;
  j["command"] = "compress";
  j["input"] = {{"path", flags.input}, {"poses", input.size()}, {"has_orientation", input.has_orientation()}};
  j["model"] = {{"path", flags.output}, {"bytes", model_bytes}};
  j["tolerance_m"] = flags.tolerance ? nlohmann::json(*flags.tolerance) : nlohmann::json(nullptr);
  j["segments"] = model.segments.size();
  j["windows"] = windows;
  j["degrees"] = degrees;
  j["input_numbers"] = c.input_numbers;
  j["model_values"] = cheb::ModelValueCount(model);
  j["model_numbers"] = c.model_numbers;
  j["compression_ratio"] = c.ratio;
  j["max_error_m"] = c.error.max;
  j["rms_error_m"] = c.error.rms;
  j["worst_stamp"] = traj::FormatSeconds(c.error.worst_stamp_ns);
  j["noise_sigma_m"] =
      std::vector<double>(model.noise_sigma.data(), model.noise_sigma.data() + model.noise_sigma.size());
  j["automatic"] = c.automatic;
  j["seconds"] = seconds;
  return j;
}

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
      const nlohmann::json report = Report(*flags, view, result, text.size(), seconds);
      const std::string report_text = report.dump(2) + "\n";
      std::vector<traj::FileToWrite> files{{flags->output, text}};
      if (!flags->json_path.empty()) files.push_back({flags->json_path, report_text});
      traj::WriteFilesAtomically(files);
      const auto windows = report["windows"].get<size_t>();
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

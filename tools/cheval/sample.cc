// `cheval sample MODEL.json (--rate HZ | --at FILE) -o OUT`: positions from a model written by
// `cheval compress`, as TUM (docs/compress.md).
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "cheval/cheb/model.h"
#include "cheval/common/error.h"
#include "cheval/common/memory.h"
#include "common.h"

namespace cheval::cli {
namespace {

struct SampleFlags {
  std::string model;
  std::optional<double> rate_hz;
  std::string at_path;
  std::string output;
};

}  // namespace

void RegisterSample(CLI::App& app, Action* action) {
  auto flags = std::make_shared<SampleFlags>();
  CLI::App* command = app.add_subcommand(
      "sample", "Positions from a model written by `cheval compress`, at a rate or at given stamps, as TUM");
  command->add_option("model", flags->model, "Model file (JSON) from cheval compress")->required();
  CLI::Option* rate = command->add_option(
      "--rate", flags->rate_hz, "Sample every 1/HZ s from the model's first stamp to its last (gaps are skipped)");
  CLI::Option* at = command->add_option(
      "--at", flags->at_path, "Sample at these stamps: a file of one stamp (s) per line, or a trajectory file");
  rate->excludes(at);
  command
      ->add_option("-o,--output", flags->output,
                   "TUM file to write (t x y z qx qy qz qw; the model stores positions only, so the "
                   "orientation is the identity)")
      ->required();
  command->callback([flags, action] {
    *action = [flags] {
      if (!flags->rate_hz && flags->at_path.empty()) throw UsageError("sample needs --rate HZ or --at FILE");
      if (flags->rate_hz && !(*flags->rate_hz > 0.0 && std::isfinite(*flags->rate_hz))) {
        throw UsageError(fmt::format("--rate must be a positive number of Hz, got {}", *flags->rate_hz));
      }
      RefuseSharedPaths({flags->model, flags->at_path}, {{"-o", flags->output}});
      const cheb::TrajectoryModel model = cheb::ReadModel(flags->model);
      if (model.dimension != 3) {
        throw InputError(
            flags->model, 0, 0,
            fmt::format("dimension: expected 3 (x y z positions) to sample positions, got {}", model.dimension));
      }
      std::vector<int64_t> stamps;
      if (flags->rate_hz) {
        if (!model.segments.empty()) {
          // Each stamp costs its stamp, its position, a TUM pose and its line of text (measured: 177
          // bytes a stamp); checked before ModelGridStamps allocates the grid.
          constexpr double kBytesPerStamp = 200;
          const double span_s =
              (static_cast<double>(model.segments.back().last_ns) - static_cast<double>(model.origin_ns)) * 1e-9;
          const double count = std::floor(span_s * *flags->rate_hz) + 1.0;
          CheckMemory({"ModelGridStamps", "rate_hz", count * kBytesPerStamp,
                       fmt::format("{:.4g} stamps over the model's {:.3f} s", count, span_s), MemoryCost::kOption});
        }
        stamps = cheb::ModelGridStamps(model, *flags->rate_hz);
      } else {
        stamps = ReadQueryStamps(flags->at_path);
        try {
          cheb::CheckModelCovers(model, stamps);
        } catch (const ComputeError& e) {
          throw ComputeError(fmt::format("--at {}: {}", flags->at_path, e.what()));
        }
      }
      Eigen::MatrixXd positions;
      cheb::CurveFromModel(model).EvaluateMany(stamps, 0, &positions);
      traj::Trajectory out(traj::Channels{traj::OrientationKind::kQuaternion, false, false, true});
      out.Reserve(static_cast<Eigen::Index>(stamps.size()));
      const double identity[4] = {0.0, 0.0, 0.0, 1.0};
      for (size_t i = 0; i < stamps.size(); ++i) {
        const Eigen::Vector3d p = positions.row(static_cast<Eigen::Index>(i)).transpose();
        out.Append(stamps[i], p.data(), identity);
      }
      traj::WriteTrajectory(flags->output, out.View(), traj::Format::kTum);
      fmt::print("{}: {} positions {} -> {} (TUM, identity orientation: the model stores positions only)\n",
                 flags->model, stamps.size(),
                 flags->rate_hz ? fmt::format("at {} Hz", *flags->rate_hz) : "at the stamps of " + flags->at_path,
                 flags->output);
    };
  });
}

}  // namespace cheval::cli

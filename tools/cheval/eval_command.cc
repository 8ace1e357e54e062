#include "eval_command.h"

#include <algorithm>
#include <filesystem>
#include <future>

#include <fmt/format.h>

#include <vector>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "progress.h"
#include "cheval/traj/stamp.h"

namespace cheval::cli {
namespace {

// One estimate's evaluation, with what is needed to print it and write its JSON.
using Evaluated = eval::EvaluationReport;

// The read options of one side: its prefixed flags where given, else the ones for both files.
traj::ReadOptions SideOptions(CLI::App* command, const EvalFlags& flags, const std::string& prefix,
                              const InputFlags& side) {
  InputFlags merged = flags.both;
  auto given = [&](const char* field) { return command->get_option(Flag(field, prefix))->count() > 0; };
  if (given("ReadOptions::format")) merged.format = side.format;
  if (given("ReadOptions::columns")) merged.columns = side.columns;
  if (given("ReadOptions::kitti_times_path")) merged.kitti_times = side.kitti_times;
  if (given("ReadOptions::topic")) merged.topics = side.topics;
  if (given("ReadOptions::record_time")) merged.bag_time = side.bag_time;
  return merged.ToReadOptions();
}

// The estimates to read: each file, or each file with each of several --est-topic (one recording,
// several estimators), named PATH:TOPIC.
struct EstimateSource {
  std::string path, name;
  traj::ReadOptions options;
};

std::vector<EstimateSource> EstimateSources(CLI::App* command, const EvalFlags& flags) {
  InputFlags side = flags.est;
  const bool per_side = command->get_option(Flag("ReadOptions::topic", "est-"))->count() > 0;
  const std::vector<std::string> topics = per_side ? flags.est.topics : flags.both.topics;
  side.topics.clear();
  InputFlags both = flags.both;
  both.topics.clear();
  EvalFlags single = flags;
  single.est = side;
  single.both = both;
  const traj::ReadOptions base = SideOptions(command, single, "est-", side);
  std::vector<EstimateSource> sources;
  for (const std::string& path : flags.estimates) {
    if (topics.empty()) sources.push_back({path, path, base});
    for (const std::string& topic : topics) {
      traj::ReadOptions options = base;
      options.topic = topic;
      sources.push_back({path, topics.size() > 1 ? path + ":" + topic : path, options});
    }
  }
  return sources;
}

}  // namespace

eval::EvaluationOptions ToEvaluationOptions(eval::MetricKind metric, const EvalFlags& flags) {
  eval::EvaluationOptions options = flags.options;
  options.metric = metric;
  if (flags.n_align) {
    // The library reads 0 as "all pairs"; a given --n-align 0 would be ignored silently.
    const OptionCheck check("AlignmentOptions");
    check(*flags.n_align >= 1, "n_align", "must be at least 1 (leave it out to align on all pairs), got {}",
          *flags.n_align);
    options.alignment.n_align = *flags.n_align;
  }
  options.association = eval::AssociationOptions::FromSeconds(flags.t_max_diff, flags.t_offset);
  options.continuous_reference = flags.association == "continuous";
  options.alignment.method = *eval::AlignmentMethodFromString(flags.align);
  options.relation = *eval::PoseRelationFromString(flags.relation);
  options.rpe.delta_unit = *eval::DeltaUnitFromString(flags.delta_unit);
  options.reference_velocity = *eval::ReferenceVelocitySourceFromString(flags.gt_velocity);
  options.estimate_velocity_body_frame = flags.velocity_frame == "body";
  options.Validate();
  options.velocity.curve.progress = Progress().Fn();  // the reference fit of C-ASE, on a terminal only
  return options;
}

std::vector<std::string> EvalInputPaths(const EvalFlags& flags) {
  std::vector<std::string> paths{flags.reference, flags.both.kitti_times, flags.ref.kitti_times, flags.est.kitti_times};
  paths.insert(paths.end(), flags.estimates.begin(), flags.estimates.end());
  return paths;
}

EvalInputs ReadEvalInputs(CLI::App* command, const EvalFlags& flags) {
  const traj::ReadOptions ref_options = SideOptions(command, flags, "ref-", flags.ref);
  const std::vector<EstimateSource> sources = EstimateSources(command, flags);
  // Read the files concurrently (reading dominates the run time); errors are reported in argument order.
  auto ref_future = std::async(std::launch::async, [&] { return traj::ReadTrajectory(flags.reference, ref_options); });
  std::vector<std::future<traj::Trajectory>> est_futures;
  for (const auto& source : sources) {
    est_futures.push_back(std::async(std::launch::async, [&source] { return traj::ReadTrajectory(source.path, source.options); }));
  }
  EvalInputs inputs{ref_future.get(), {}, {}};
  for (const auto& source : sources) inputs.estimate_names.push_back(source.name);
  for (auto& f : est_futures) inputs.estimates.push_back(f.get());
  return inputs;
}

namespace {

// evo's statistics in its order (sorted by name).
std::vector<std::pair<std::string, double>> SortedStats(const eval::ErrorStatistics& s) {
  return {{"max", s.max}, {"mean", s.mean}, {"median", s.median}, {"min", s.min},
          {"rmse", s.rmse}, {"sse", s.sse},  {"std", s.std}};
}

void PrintResult(const Evaluated& e, Eigen::Index ref_poses) {
  const eval::EvaluationResult& r = e.result;
  const Eigen::Index shorter = std::min(ref_poses, e.estimate_poses);
  if (r.association.by_index) {
    fmt::print("{}: {} pairs (no stamps: pose i with pose i)\n", e.estimate_path, r.association.size());
  } else if (r.continuous_reference) {
    fmt::print("{}: {} of {} estimate stamps inside the reference's Chebyshev curve (continuous reference)\n",
               e.estimate_path, r.association.size(), e.estimate_poses);
  } else {
    fmt::print("{}: found {} of max. {} possible matching timestamps (t_max_diff {} s, t_offset {} s)\n",
               e.estimate_path, r.association.size(), shorter, e.options.association.max_diff_s(),
               e.options.association.offset_s());
  }
  fmt::print("{}\n\n", r.title);
  if (!r.ase) {
    for (const auto& [name, value] : SortedStats(r.stats)) fmt::print("{:>10}\t{:.6f}\n", name, value);
  } else {
    // The ASE and its parts side by side.
    std::vector<std::pair<std::string, const eval::ErrorStatistics*>> columns = {{"ASE", &r.stats}};
    if (r.ase->has_rotation) columns.push_back({"rotation", &r.rotation_stats});
    columns.push_back({"position", &r.position_stats});
    if (r.ase->has_velocity) columns.push_back({"velocity", &r.velocity_stats});
    fmt::print("{:>10}", "");
    for (const auto& column : columns) fmt::print("\t{:>12}", column.first);
    fmt::print("\n");
    for (size_t row = 0; row < 7; ++row) {
      fmt::print("{:>10}", SortedStats(r.stats)[row].first);
      for (const auto& column : columns) fmt::print("\t{:>12.6f}", SortedStats(*column.second)[row].second);
      fmt::print("\n");
    }
  }
  if (r.drift) {
    fmt::print("\nKITTI drift over 100..800 m of reference path ({} segments): translation {:.4f} %, rotation "
               "{:.6f} deg/m\n",
               r.drift->segments, r.drift->translation_percent, r.drift->rotation_deg_per_m);
  }
  fmt::print("\n");
}

// Several estimates: one table, the paper's Table II form.
void PrintComparison(const std::vector<Evaluated>& all) {
  size_t width = 8;
  for (const Evaluated& e : all) width = std::max(width, e.estimate_path.size());
  const eval::EvaluationResult& first = all.front().result;
  fmt::print("{} {}, {} estimates\n", first.title.substr(0, first.title.find('\n')),
             first.title.substr(first.title.rfind('\n') + 1), all.size());
  fmt::print("{:<{}}  {:>12}  {:>12}  {:>12}  {:>8}\n", "estimate", width, "rmse", "std", "median", "pairs");
  for (const Evaluated& e : all) {
    fmt::print("{:<{}}  {:>12.6f}  {:>12.6f}  {:>12.6f}  {:>8}\n", e.estimate_path, width, e.result.stats.rmse,
               e.result.stats.std, e.result.stats.median, e.result.stats.n);
  }
}

void Run(CLI::App* command, eval::MetricKind metric, const EvalFlags& flags) {
  const eval::EvaluationOptions options = ToEvaluationOptions(metric, flags);
  RefuseSharedPaths(EvalInputPaths(flags), {{"--json", flags.json_path}, {"--errors", flags.errors_path}});
  const EvalInputs inputs = ReadEvalInputs(command, flags);
  const traj::Trajectory& ref = inputs.reference;
  const std::vector<traj::Trajectory>& ests = inputs.estimates;

  // Everything is evaluated before anything is written or printed: an error leaves no output file.
  std::vector<Evaluated> all;
  for (size_t k = 0; k < ests.size(); ++k) {
    Evaluated e;
    e.reference_path = flags.reference;
    e.reference_poses = ref.size();
    e.estimate_path = inputs.estimate_names[k];
    e.estimate_poses = ests[k].size();
    e.options = options;
    e.result = eval::Evaluate(ref.View(), ests[k].View(), options);
    all.push_back(std::move(e));
  }
  std::string json_text, errors_text;
  if (!flags.json_path.empty()) json_text = eval::EvaluationJson(all);
  if (!flags.errors_path.empty()) errors_text = eval::EvaluationErrorsCsv(all);

  for (const Evaluated& e : all) PrintResult(e, ref.size());
  if (all.size() > 1) PrintComparison(all);
  std::vector<OutputFile> files;
  if (!flags.json_path.empty()) files.push_back({flags.json_path, json_text});
  if (!flags.errors_path.empty()) files.push_back({flags.errors_path, errors_text});
  WriteOutputs(files);
}

}  // namespace

void AddRelationFlag(CLI::App* command, EvalFlags* flags) {
  command->add_option("-r," + Flag("EvaluationOptions::relation"), flags->relation, "Pose relation (evo's -r names)")
      ->check(CLI::IsMember({"trans_part", "rot_part", "full", "angle_deg", "angle_rad", "point_distance"}))
      ->capture_default_str();
}

void AddEvalInputFlags(CLI::App* command, EvalFlags* flags) {
  command->add_option("reference", flags->reference, "Reference (ground-truth) trajectory file")->required();
  command->add_option("estimates", flags->estimates, "One or more estimated trajectory files")->required();
  AddInputFlags(command, &flags->both);
  AddInputFlags(command, &flags->ref, "ref-");
  AddInputFlags(command, &flags->est, "est-");
  command->add_option(Flag("AlignmentOptions::method"), flags->align, "Alignment of each estimate onto the reference")
      ->check(CLI::IsMember({"none", "origin", "se3", "sim3", "scale", "posyaw", "full"}))
      ->capture_default_str();
  command->add_option(Flag("AlignmentOptions::n_align"), flags->n_align, "Solve the alignment from the first N pairs only (default: all)");
  command->add_option(Flag("AssociationOptions::max_diff_ns"), flags->t_max_diff, "Largest stamp difference of an associated pair, seconds")
      ->capture_default_str();
  command->add_option(Flag("AssociationOptions::offset_ns"), flags->t_offset, "Added to the estimate stamps: est + offset = ref, seconds")
      ->capture_default_str();
  command->add_option(Flag("EvaluationOptions::continuous_reference"), flags->association,
                      "nearest: each estimate pose with the nearest reference pose (evo); continuous: the reference's "
                      "Chebyshev curve evaluated at the exact estimate stamps")
      ->check(CLI::IsMember({"nearest", "continuous"}))
      ->capture_default_str();
}

void AddStateVelocityFlags(CLI::App* command, EvalFlags* flags) {
  command->add_option(Flag("EvaluationOptions::reference_velocity"), flags->gt_velocity,
                      "Reference velocity: given (its columns), chebyshev or central (from its positions); "
                      "auto = given if present, else chebyshev")
      ->check(CLI::IsMember({"auto", "given", "chebyshev", "central"}))
      ->capture_default_str();
  command->add_option(Flag("EvaluationOptions::estimate_velocity_body_frame"), flags->velocity_frame,
                      "Frame of the estimate's velocity columns; body is rotated by the estimate's orientation")
      ->check(CLI::IsMember({"world", "body"}))
      ->capture_default_str();
}

void RegisterEvalCommand(CLI::App& app, Action* action, eval::MetricKind metric, const std::string& description,
                         const std::function<void(CLI::App*, EvalFlags*)>& add_flags) {
  auto flags = std::make_shared<EvalFlags>();
  CLI::App* command = app.add_subcommand(std::string(eval::ToString(metric)), description);
  AddEvalInputFlags(command, flags.get());
  command->add_option("--json", flags->json_path, "Write the result as JSON (an array for several estimates)");
  command->add_option("--errors", flags->errors_path, "Write the per-pair errors as CSV");
  add_flags(command, flags.get());
  command->callback([command, metric, flags, action] {
    *action = [command, metric, flags] { Run(command, metric, *flags); };
  });
}

}  // namespace cheval::cli

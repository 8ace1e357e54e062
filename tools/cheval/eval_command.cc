#include "eval_command.h"

#include <algorithm>
#include <filesystem>
#include <future>

#include <fmt/format.h>

#include <vector>

#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/eval/extrinsic.h"
#include "cheval/eval/res_file.h"
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

std::string ResolvedAlignment(const EvalFlags& flags) {
  const bool evo = flags.evo_align || flags.evo_scale || flags.evo_align_origin;
  if (!evo) return flags.align;
  if (flags.evo_align_origin && (flags.evo_align || flags.evo_scale)) {
    throw UsageError("--align_origin with -a/-s: cheval aligns once; give --align origin, or -a/-s alone");
  }
  const std::string method = flags.evo_align_origin ? "origin"
                             : flags.evo_align     ? (flags.evo_scale ? "sim3" : "se3")
                                                   : "scale";
  if (flags.align_given && flags.align != method) {
    throw UsageError(fmt::format("--align {} contradicts evo's alignment flags (-a/-s/--align_origin mean --align {})",
                                 flags.align, method));
  }
  return method;
}

std::string UnknownFlags(const CLI::App& app, const std::vector<std::string>& arguments) {
  const std::vector<CLI::App*> commands = app.get_subcommands();
  const CLI::App* command = commands.empty() ? &app : commands.front();
  std::vector<std::string> known;
  for (const CLI::Option* option : command->get_options()) {
    for (const std::string& name : option->get_lnames()) known.push_back("--" + name);
    for (const std::string& name : option->get_snames()) known.push_back("-" + name);
  }
  return UnknownFlagsMessage(arguments, known, commands.empty() ? "" : command->get_name());
}

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
  options.alignment.method = *eval::AlignmentMethodFromString(ResolvedAlignment(flags));
  options.relation = *eval::PoseRelationFromString(flags.relation);
  options.rpe.delta_unit = *eval::DeltaUnitFromString(flags.delta_unit);
  options.reference_velocity = *eval::ReferenceVelocitySourceFromString(flags.gt_velocity);
  options.estimate_velocity_body_frame = flags.velocity_frame == "body";
  options.Validate();
  options.velocity.curve.progress = Progress().Fn();  // the reference fit of C-ASE, on a terminal only
  return options;
}

std::vector<std::string> EvalInputPaths(const EvalFlags& flags) {
  std::vector<std::string> paths{flags.reference,       flags.both.kitti_times,     flags.ref.kitti_times,
                                 flags.est.kitti_times,   flags.transform_left,       flags.transform_right,
                                 flags.ref_transform_left, flags.ref_transform_right};
  paths.insert(paths.end(), flags.estimates.begin(), flags.estimates.end());
  return paths;
}

namespace {

// `t` transformed by the extrinsic files given (either may be empty), before association.
void ApplyExtrinsics(const std::string& left_path, const std::string& right_path, traj::Trajectory* t) {
  if (left_path.empty() && right_path.empty()) return;
  std::optional<eval::Extrinsic> left, right;
  if (!left_path.empty()) left = eval::ReadExtrinsic(left_path);
  if (!right_path.empty()) right = eval::ReadExtrinsic(right_path);
  *t = eval::TransformTrajectory(t->View(), left ? &*left : nullptr, right ? &*right : nullptr);
}

// --label values in order, else each source's name without its folders.
std::vector<std::string> EstimateLabels(const EvalFlags& flags, const std::vector<EstimateSource>& sources) {
  if (!flags.labels.empty()) {
    if (flags.labels.size() != sources.size()) {
      throw UsageError(fmt::format("--label given {} times for {} estimates: give one per estimate, in order",
                                   flags.labels.size(), sources.size()));
    }
    return flags.labels;
  }
  std::vector<std::string> labels;
  for (const EstimateSource& source : sources) {
    const std::string file = std::filesystem::path(source.path).filename().string();
    labels.push_back(file + source.name.substr(source.path.size()));  // keeps ":TOPIC"
  }
  return labels;
}

}  // namespace

EvalInputs ReadEvalInputs(CLI::App* command, const EvalFlags& flags) {
  const traj::ReadOptions ref_options = SideOptions(command, flags, "ref-", flags.ref);
  const std::vector<EstimateSource> sources = EstimateSources(command, flags);
  // Read the files concurrently (reading dominates the run time); errors are reported in argument order.
  EvalInputs inputs;
  inputs.estimate_formats.resize(sources.size());
  auto ref_future = std::async(std::launch::async, [&] {
    return traj::ReadTrajectory(flags.reference, ref_options, &inputs.reference_format);
  });
  std::vector<std::future<traj::Trajectory>> est_futures;
  for (size_t k = 0; k < sources.size(); ++k) {
    est_futures.push_back(std::async(std::launch::async, [&sources, &inputs, k] {
      return traj::ReadTrajectory(sources[k].path, sources[k].options, &inputs.estimate_formats[k]);
    }));
  }
  inputs.reference = ref_future.get();
  for (const auto& source : sources) inputs.estimate_names.push_back(source.name);
  inputs.estimate_labels = EstimateLabels(flags, sources);
  for (auto& f : est_futures) inputs.estimates.push_back(f.get());
  ApplyExtrinsics(flags.ref_transform_left, flags.ref_transform_right, &inputs.reference);
  for (traj::Trajectory& estimate : inputs.estimates) {
    ApplyExtrinsics(flags.transform_left, flags.transform_right, &estimate);
  }
  return inputs;
}

namespace {

eval::EvoStampSeconds EvoSecondsOf(traj::Format format) {
  // evo's EuRoC and pose CSV readers divide integer nanoseconds by 1e9; its text-second formats parse decimals.
  const bool nanoseconds = format == traj::Format::kEuroc || format == traj::Format::kVins;
  return nanoseconds ? eval::EvoStampSeconds::kNanosecondsOver1e9 : eval::EvoStampSeconds::kDecimal;
}

}  // namespace

eval::EvaluationOptions OptionsForEstimate(eval::EvaluationOptions options, const EvalInputs& inputs, size_t k) {
  options.association.ref_seconds = EvoSecondsOf(inputs.reference_format);
  options.association.est_seconds = EvoSecondsOf(inputs.estimate_formats[k]);
  return options;
}

namespace {

// evo's statistics in its order (sorted by name).
std::vector<std::pair<std::string, double>> SortedStats(const eval::ErrorStatistics& s) {
  return {{"max", s.max}, {"mean", s.mean}, {"median", s.median}, {"min", s.min},
          {"rmse", s.rmse}, {"sse", s.sse},  {"std", s.std}};
}

void PrintResult(const Evaluated& e, Eigen::Index ref_poses) {
  const std::string& name = e.estimate_label.empty() ? e.estimate_path : e.estimate_label;
  const eval::EvaluationResult& r = e.result;
  const Eigen::Index shorter = std::min(ref_poses, e.estimate_poses);
  if (r.association.by_index) {
    fmt::print("{}: {} pairs (no stamps: pose i with pose i)\n", name, r.association.size());
  } else if (r.continuous_reference) {
    fmt::print("{}: {} of {} estimate stamps inside the reference's Chebyshev curve (continuous reference)\n",
               name, r.association.size(), e.estimate_poses);
  } else {
    fmt::print("{}: found {} of max. {} possible matching timestamps (t_max_diff {} s, t_offset {} s)\n",
               name, r.association.size(), shorter, e.options.association.max_diff_s(),
               e.options.association.offset_s());
  }
  fmt::print("{}\n\n", r.title);
  if (!r.ase) {
    for (const auto& [stat, value] : SortedStats(r.stats)) fmt::print("{:>10}\t{:.6f}\n", stat, value);
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
  if (r.drift && r.drift->segments == 0) {
    fmt::print("\nKITTI drift over 100..800 m of reference path: none (path shorter than 100 m)\n");
  } else if (r.drift) {
    fmt::print("\nKITTI drift over 100..800 m of reference path ({} segments): translation {:.4f} %, rotation "
               "{:.6f} deg/m\n",
               r.drift->segments, r.drift->translation_percent, r.drift->rotation_deg_per_m);
  }
  fmt::print("\n");
}

// Several estimates: one table, the paper's Table II form.
void PrintComparison(const std::vector<Evaluated>& all, const std::vector<std::string>& labels) {
  size_t width = 8;
  for (const std::string& label : labels) width = std::max(width, label.size());
  const eval::EvaluationResult& first = all.front().result;
  fmt::print("{} {}, {} estimates\n", first.title.substr(0, first.title.find('\n')),
             first.title.substr(first.title.rfind('\n') + 1), all.size());
  fmt::print("{:<{}}  {:>12}  {:>12}  {:>12}  {:>8}\n", "estimate", width, "rmse", "std", "median", "pairs");
  for (size_t k = 0; k < all.size(); ++k) {
    const Evaluated& e = all[k];
    fmt::print("{:<{}}  {:>12.6f}  {:>12.6f}  {:>12.6f}  {:>8}\n", labels[k], width, e.result.stats.rmse,
               e.result.stats.std, e.result.stats.median, e.result.stats.n);
  }
}

void Run(CLI::App* command, eval::MetricKind metric, const EvalFlags& flags) {
  const eval::EvaluationOptions options = ToEvaluationOptions(metric, flags);
  RefuseSharedPaths(EvalInputPaths(flags), {{"--json", flags.json_path},
                                            {"--errors", flags.errors_path},
                                            {"--save-results", flags.save_results}});
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
    // The JSON names a label only when --label gave one (its default, the file name, is in the path).
    if (!flags.labels.empty()) e.estimate_label = inputs.estimate_labels[k];
    e.estimate_poses = ests[k].size();
    e.options = OptionsForEstimate(options, inputs, k);
    e.result = eval::Evaluate(ref.View(), ests[k].View(), e.options);
    all.push_back(std::move(e));
  }
  std::string json_text, errors_text, zip_bytes;
  if (!flags.save_results.empty()) {
    if (all.size() != 1) {
      throw UsageError(fmt::format("--save-results writes evo's result file of one estimate, and {} were given: run "
                                   "once per estimate",
                                   all.size()));
    }
    zip_bytes = eval::EvoResultZip(all.front());
  }
  if (!flags.json_path.empty()) json_text = eval::EvaluationJson(all);
  if (!flags.errors_path.empty()) errors_text = eval::EvaluationErrorsCsv(all);

  // Warnings once each (several estimates against one reference repeat the reference's).
  std::vector<std::string> warned;
  for (const Evaluated& e : all) {
    for (const std::string& w : e.result.warnings) {
      if (std::find(warned.begin(), warned.end(), w) != warned.end()) continue;
      warned.push_back(w);
      fmt::print(stderr, "{}: warning: {}\n", flags.reference, Spell(w));
    }
  }
  for (const Evaluated& e : all) PrintResult(e, ref.size());
  if (all.size() > 1) PrintComparison(all, inputs.estimate_labels);
  std::vector<OutputFile> files;
  if (!flags.json_path.empty()) files.push_back({flags.json_path, json_text});
  if (!flags.errors_path.empty()) files.push_back({flags.errors_path, errors_text});
  if (!flags.save_results.empty()) files.push_back({flags.save_results, zip_bytes});
  WriteOutputs(files);
}

}  // namespace

void AddRelationFlag(CLI::App* command, EvalFlags* flags) {
  command->add_option(Names("EvaluationOptions::relation", "", "-r"), flags->relation, "Pose relation (evo's -r names)")
      ->check(CLI::IsMember({"trans_part", "rot_part", "full", "angle_deg", "angle_rad", "point_distance"}))
      ->capture_default_str();
}

void AddEvalInputFlags(CLI::App* command, EvalFlags* flags) {
  command->add_option("reference", flags->reference, "Reference (ground-truth) trajectory file")->required();
  command->add_option("estimates", flags->estimates, "One or more estimated trajectory files")->required();
  AddInputFlags(command, &flags->both);
  AddInputFlags(command, &flags->ref, "ref-");
  AddInputFlags(command, &flags->est, "est-");
  // --align METHOD; a bare --align (evo's flag) means se3 like evo's -a.
  command
      ->add_option_function<std::string>(
          Flag("AlignmentOptions::method"),
          [flags](const std::string& method) {
            if (method.empty()) {
              flags->evo_align = true;
            } else {
              flags->align = method;
              flags->align_given = true;
            }
          },
          fmt::format("Alignment of each estimate onto the reference (default: {}; alone: se3, as evo's --align)",
                      flags->align))
      ->expected(0, 1)
      ->check(CLI::IsMember({"", "none", "origin", "se3", "sim3", "scale", "posyaw", "full"}));
  command->add_flag("-a", flags->evo_align, "evo's -a: --align se3 (with -s: sim3)");
  command->add_flag("-s,--correct_scale", flags->evo_scale, "evo's -s: --align scale (with -a: sim3)");
  command->add_flag("--align_origin", flags->evo_align_origin, "evo's --align_origin: --align origin");
  command->add_option("--label", flags->labels,
                      "Name of each estimate in the tables and the JSON, one per estimate in order (default: the file "
                      "name)")
      ->allow_extra_args(false);
  command->add_option(FlagNames("--transform-left"), flags->transform_left,
                      "Extrinsic applied to each estimate from the left (world frame), T*P: .json x y z qx qy qz qw "
                      "[scale], .npy or text 4x4 matrix");
  command->add_option(FlagNames("--transform-right"), flags->transform_right,
                      "Extrinsic applied to each estimate from the right (body frame), P*T, e.g. estimator body to "
                      "the reference's IMU");
  command->add_option("--ref-transform-left", flags->ref_transform_left, "Like --transform-left, for the reference");
  command->add_option("--ref-transform-right", flags->ref_transform_right, "Like --transform-right, for the reference");
  command->add_flag("-v,--verbose", flags->verbose, "Accepted for evo's -v; cheval always prints these lines");
  command->add_option(Names("AlignmentOptions::n_align"), flags->n_align, "Solve the alignment from the first N pairs only (default: all)");
  command->add_option(Names("AssociationOptions::max_diff_ns"), flags->t_max_diff, "Largest stamp difference of an associated pair, seconds")
      ->capture_default_str();
  command->add_option(Names("AssociationOptions::offset_ns"), flags->t_offset, "Added to the estimate stamps: est + offset = ref, seconds")
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
  command->add_option(FlagNames("--save-results"), flags->save_results,
                      "Write evo's result zip (what evo_res and file_interface.load_res_file read); one estimate");
  add_flags(command, flags.get());
  command->callback([command, metric, flags, action] {
    *action = [command, metric, flags] { Run(command, metric, *flags); };
  });
}

}  // namespace cheval::cli

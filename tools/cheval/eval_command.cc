#include "eval_command.h"

#include <algorithm>
#include <filesystem>
#include <future>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/traj/stamp.h"

namespace cheval::cli {
namespace {

using Json = nlohmann::ordered_json;

// One estimate's evaluation, with what is needed to print it.
struct Evaluated {
  std::string path;
  Eigen::Index poses = 0;
  eval::EvaluationResult result;
};

// The read options of one side: its prefixed flags where given, else the ones for both files.
traj::ReadOptions SideOptions(CLI::App* command, const EvalFlags& flags, const std::string& prefix,
                              const InputFlags& side) {
  InputFlags merged = flags.both;
  auto given = [&](const std::string& name) { return command->get_option("--" + prefix + name)->count() > 0; };
  if (given("format")) merged.format = side.format;
  if (given("columns")) merged.columns = side.columns;
  if (given("kitti-times")) merged.kitti_times = side.kitti_times;
  return merged.ToReadOptions();
}

// --delta-unit: the full name, or evo's letter f, m, d, r.
eval::DeltaUnit ParseDeltaUnit(const std::string& name) {
  if (name == "f") return eval::DeltaUnit::kFrames;
  if (name == "m") return eval::DeltaUnit::kMeters;
  if (name == "d") return eval::DeltaUnit::kDegrees;
  if (name == "r") return eval::DeltaUnit::kRadians;
  return *eval::DeltaUnitFromString(name);
}

eval::EvaluationOptions ToOptions(eval::MetricKind metric, const EvalFlags& flags) {
  eval::EvaluationOptions options;
  options.metric = metric;
  options.association.max_diff_ns = eval::SecondsToNanoseconds(flags.t_max_diff, "--t-max-diff");
  options.association.offset_ns = eval::SecondsToNanoseconds(flags.t_offset, "--t-offset");
  if (options.association.max_diff_ns < 0) throw UsageError("--t-max-diff must be >= 0");
  options.continuous_reference = flags.association == "continuous";
  options.alignment.method = *eval::AlignmentMethodFromString(flags.align);
  if (flags.n_align < 0) throw UsageError(fmt::format("--n-align must be positive, got {}", flags.n_align));
  options.alignment.n_align = flags.n_align;
  if (flags.n_align > 0 && options.alignment.method == eval::AlignmentMethod::kNone) {
    throw UsageError("--n-align needs --align (se3, sim3, scale, posyaw or full)");
  }
  options.relation = *eval::PoseRelationFromString(flags.relation);
  options.rpe.delta = flags.delta;
  options.rpe.delta_unit = ParseDeltaUnit(flags.delta_unit);
  options.rpe.all_pairs = flags.all_pairs;
  options.kitti_drift = flags.kitti_drift;
  options.reference_velocity = *eval::ReferenceVelocitySourceFromString(flags.gt_velocity);
  options.estimate_velocity_body_frame = flags.velocity_frame == "body";
  options.pose_only = flags.pose_only;
  if (flags.pose_only && flags.velocity_frame == "body") throw UsageError("--pose-only ignores velocity: drop --velocity-frame");
  return options;
}

std::string Unit(const eval::EvaluationResult& r) { return r.unit.empty() ? "unit-less" : r.unit; }
std::string_view MetricName(eval::MetricKind metric) {
  return metric == eval::MetricKind::kApe ? "APE" : metric == eval::MetricKind::kRpe ? "RPE" : "ASE";
}

// evo's statistics in its order (sorted by name).
std::vector<std::pair<std::string, double>> SortedStats(const eval::ErrorStatistics& s) {
  return {{"max", s.max}, {"mean", s.mean}, {"median", s.median}, {"min", s.min},
          {"rmse", s.rmse}, {"sse", s.sse},  {"std", s.std}};
}

void PrintResult(const EvalFlags& flags, const Evaluated& e, Eigen::Index ref_poses) {
  const eval::EvaluationResult& r = e.result;
  const Eigen::Index shorter = std::min(ref_poses, e.poses);
  if (r.association.by_index) {
    fmt::print("{}: {} pairs (no stamps: pose i with pose i)\n", e.path, r.association.size());
  } else if (r.continuous_reference) {
    fmt::print("{}: {} of {} estimate stamps inside the reference's Chebyshev curve (continuous reference)\n", e.path,
               r.association.size(), e.poses);
  } else {
    fmt::print("{}: found {} of max. {} possible matching timestamps (t_max_diff {} s, t_offset {} s)\n", e.path,
               r.association.size(), shorter, flags.t_max_diff, flags.t_offset);
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
  for (const Evaluated& e : all) width = std::max(width, e.path.size());
  const eval::EvaluationResult& first = all.front().result;
  fmt::print("{} {}, {} estimates\n", first.title.substr(0, first.title.find('\n')),
             first.title.substr(first.title.rfind('\n') + 1), all.size());
  fmt::print("{:<{}}  {:>12}  {:>12}  {:>12}  {:>8}\n", "estimate", width, "rmse", "std", "median", "pairs");
  for (const Evaluated& e : all) {
    fmt::print("{:<{}}  {:>12.6f}  {:>12.6f}  {:>12.6f}  {:>8}\n", e.path, width, e.result.stats.rmse,
               e.result.stats.std, e.result.stats.median, e.result.stats.n);
  }
}

Json StatsJson(const eval::ErrorStatistics& s) {
  return Json{{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
              {"min", s.min},   {"max", s.max},   {"sse", s.sse},       {"n", s.n}};
}

Json ResultJson(const EvalFlags& flags, eval::MetricKind metric, Eigen::Index ref_poses, const Evaluated& e) {
  const eval::EvaluationResult& r = e.result;
  const eval::Similarity& s = r.alignment.transform;
  Json j;
  j["command"] = std::string(eval::ToString(metric));
  j["reference"] = {{"path", flags.reference}, {"poses", ref_poses}};
  j["estimate"] = {{"path", e.path}, {"poses", e.poses}};
  j["association"] = {{"pairs", r.association.size()}, {"max_diff", flags.t_max_diff}, {"offset", flags.t_offset}};
  j["association"]["method"] = r.association.by_index ? "index" : flags.association;
  Json rotation = Json::array();
  for (int row = 0; row < 3; ++row) rotation.push_back({s.rotation(row, 0), s.rotation(row, 1), s.rotation(row, 2)});
  j["alignment"] = {{"method", std::string(eval::ToString(r.alignment.method))},
                    {"rotation", rotation},
                    {"translation", {s.translation.x(), s.translation.y(), s.translation.z()}},
                    {"scale", s.scale}};
  if (r.alignment.method != eval::AlignmentMethod::kNone) j["alignment"]["pairs_used"] = r.alignment.pairs_used;
  j["metric"] = {{"name", std::string(MetricName(metric))}, {"relation", r.relation}, {"unit", Unit(r)}};
  if (metric == eval::MetricKind::kRpe) {
    j["metric"]["delta"] = flags.delta;
    j["metric"]["delta_unit"] = std::string(eval::ToString(ParseDeltaUnit(flags.delta_unit)));
    j["metric"]["all_pairs"] = flags.all_pairs;
  }
  j["stats"] = StatsJson(r.stats);
  if (r.ase) {
    j["parts"] = Json::object();
    if (r.ase->has_rotation) j["parts"]["rotation"] = StatsJson(r.rotation_stats);
    j["parts"]["position"] = StatsJson(r.position_stats);
    if (r.ase->has_velocity) j["parts"]["velocity"] = StatsJson(r.velocity_stats);
    j["velocity_source"] = r.velocity_source;
  }
  if (r.drift) {
    Json lengths = Json::array();
    for (const auto& l : r.drift->lengths) {
      lengths.push_back({{"length_m", l.length_m}, {"translation_percent", l.translation_percent},
                         {"rotation_deg_per_m", l.rotation_deg_per_m}, {"segments", l.segments}});
    }
    j["drift"] = {{"translation_percent", r.drift->translation_percent},
                  {"rotation_deg_per_m", r.drift->rotation_deg_per_m},
                  {"segments", r.drift->segments},
                  {"lengths", lengths}};
  }
  return j;
}

// Per-pair CSV: stamp (and the pair's second stamp for RPE), error, ASE parts; with several
// estimates the first column names the estimate.
std::string ErrorsCsv(const std::vector<Evaluated>& all, eval::MetricKind metric) {
  const bool several = all.size() > 1;
  const eval::EvaluationResult& first = all.front().result;
  std::string header = several ? "estimate," : "";
  header += metric == eval::MetricKind::kRpe ? "stamp,stamp_end,error" : "stamp,error";
  if (first.ase) {
    if (first.ase->has_rotation) header += ",rotation";
    header += ",position";
    if (first.ase->has_velocity) header += ",velocity";
  }
  fmt::memory_buffer out;
  auto it = std::back_inserter(out);
  fmt::format_to(it, "{}\n", header);
  for (const Evaluated& e : all) {
    const eval::EvaluationResult& r = e.result;
    for (size_t k = 0; k < r.errors.size(); ++k) {
      if (several) fmt::format_to(it, "{},", e.path);
      fmt::format_to(it, "{}", traj::FormatSeconds(r.stamps_ns[k]));
      if (metric == eval::MetricKind::kRpe) fmt::format_to(it, ",{}", traj::FormatSeconds(r.stamps_end_ns[k]));
      fmt::format_to(it, ",{}", r.errors[k]);
      if (r.ase) {
        if (r.ase->has_rotation) fmt::format_to(it, ",{}", r.ase->rotation[k]);
        fmt::format_to(it, ",{}", r.ase->position[k]);
        if (r.ase->has_velocity) fmt::format_to(it, ",{}", r.ase->velocity[k]);
      }
      fmt::format_to(it, "\n");
    }
  }
  return fmt::to_string(out);
}

void Run(CLI::App* command, eval::MetricKind metric, const EvalFlags& flags) {
  const eval::EvaluationOptions options = ToOptions(metric, flags);
  const traj::ReadOptions ref_options = SideOptions(command, flags, "ref-", flags.ref);
  const traj::ReadOptions est_options = SideOptions(command, flags, "est-", flags.est);
  // Read the files concurrently (reading dominates the run time); errors are reported in argument order.
  auto ref_future = std::async(std::launch::async, [&] { return traj::ReadTrajectory(flags.reference, ref_options); });
  std::vector<std::future<traj::Trajectory>> est_futures;
  for (const std::string& path : flags.estimates) {
    est_futures.push_back(std::async(std::launch::async, [&, path] { return traj::ReadTrajectory(path, est_options); }));
  }
  const traj::Trajectory ref = ref_future.get();
  std::vector<traj::Trajectory> ests;
  for (auto& f : est_futures) ests.push_back(f.get());

  // Everything is evaluated before anything is written or printed: an error leaves no output file.
  std::vector<Evaluated> all;
  for (size_t k = 0; k < ests.size(); ++k) {
    all.push_back({flags.estimates[k], ests[k].size(), eval::Evaluate(ref.View(), ests[k].View(), options)});
  }
  std::string json_text, errors_text;
  if (!flags.json_path.empty()) {
    Json j = Json::array();
    for (const Evaluated& e : all) j.push_back(ResultJson(flags, metric, ref.size(), e));
    json_text = (all.size() == 1 ? j[0] : j).dump(2) + "\n";
  }
  if (!flags.errors_path.empty()) errors_text = ErrorsCsv(all, metric);

  for (const Evaluated& e : all) PrintResult(flags, e, ref.size());
  if (all.size() > 1) PrintComparison(all);
  if (!flags.json_path.empty()) traj::WriteFileAtomically(flags.json_path, json_text);
  if (!flags.errors_path.empty()) traj::WriteFileAtomically(flags.errors_path, errors_text);
}

}  // namespace

void AddRelationFlag(CLI::App* command, EvalFlags* flags) {
  command->add_option("-r,--relation", flags->relation, "Pose relation (evo's -r names)")
      ->check(CLI::IsMember({"trans_part", "rot_part", "full", "angle_deg", "angle_rad", "point_distance"}))
      ->capture_default_str();
}

void RegisterEvalCommand(CLI::App& app, Action* action, eval::MetricKind metric, const std::string& description,
                         const std::function<void(CLI::App*, EvalFlags*)>& add_flags) {
  auto flags = std::make_shared<EvalFlags>();
  CLI::App* command = app.add_subcommand(std::string(eval::ToString(metric)), description);
  command->add_option("reference", flags->reference, "Reference (ground-truth) trajectory file")->required();
  command->add_option("estimates", flags->estimates, "One or more estimated trajectory files")->required();
  AddInputFlags(command, &flags->both);
  AddInputFlags(command, &flags->ref, "ref-");
  AddInputFlags(command, &flags->est, "est-");
  command->add_option("--align", flags->align, "Alignment of each estimate onto the reference")
      ->check(CLI::IsMember({"none", "origin", "se3", "sim3", "scale", "posyaw", "full"}))
      ->capture_default_str();
  command->add_option("--n-align", flags->n_align, "Solve the alignment from the first N pairs only (default: all)");
  command->add_option("--t-max-diff", flags->t_max_diff, "Largest stamp difference of an associated pair, seconds")
      ->capture_default_str();
  command->add_option("--t-offset", flags->t_offset, "Added to the estimate stamps: est + offset = ref, seconds")
      ->capture_default_str();
  command->add_option("--association", flags->association,
                      "nearest: each estimate pose with the nearest reference pose (evo); continuous: the reference's "
                      "Chebyshev curve evaluated at the exact estimate stamps")
      ->check(CLI::IsMember({"nearest", "continuous"}))
      ->capture_default_str();
  command->add_option("--json", flags->json_path, "Write the result as JSON (an array for several estimates)");
  command->add_option("--errors", flags->errors_path, "Write the per-pair errors as CSV");
  add_flags(command, flags.get());
  command->callback([command, metric, flags, action] {
    *action = [command, metric, flags] { Run(command, metric, *flags); };
  });
}

}  // namespace cheval::cli

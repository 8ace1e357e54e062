// `cheval table EXPERIMENT -o table.md [--json table.json] [-j N] [--rpg]`: a whole experiment
// (rpg_trajectory_evaluation's folder layout or a YAML file) evaluated into one table of statistics
// over trials (docs/table.md).
#include <chrono>
#include <filesystem>
#include <regex>
#include <sstream>

#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/table/table.h"
#include "common.h"
#include "progress.h"

namespace cheval::cli {
namespace {

struct TableFlags {
  std::string experiment, output, json, latex, csv, html, markdown, metrics, title;
  int jobs = 1;
  bool rpg = false, no_cache = false;
};

// The command giving a cheval-mode metric of one run by hand (REF, EST standing for its files).
std::string Command(const table::Experiment& e, const std::string& metric) {
  const table::RunSpec& run = e.runs.front();
  std::string common = fmt::format("REF EST {} {}", Flag("AlignmentOptions::method"), run.align);
  if (run.align_frames > 0) common += fmt::format(" {} {}", Flag("AlignmentOptions::n_align"), run.align_frames);
  common += fmt::format(" {} {}", Flag("AssociationOptions::max_diff_ns"), e.max_diff_s);
  static const std::regex rpe(R"(rpe_(trans|rot)_(.+)m)");
  std::smatch m;
  const std::string stat = fmt::format("  # {}", e.statistic);
  if (metric == "ape_trans" || metric == "ape_rot") {
    return fmt::format("cheval ape {} {} {}{}", common, Flag("EvaluationOptions::relation"),
                       metric == "ape_trans" ? "trans_part" : "angle_deg", stat);
  }
  if (std::regex_match(metric, m, rpe)) {
    return fmt::format("cheval rpe {} {} {} {} {} {} meters{}", common, Flag("EvaluationOptions::relation"),
                       m[1] == "trans" ? "trans_part" : "angle_deg", Flag("RpeOptions::delta"), m[2].str(),
                       Flag("RpeOptions::delta_unit"), stat);
  }
  if (metric == "ase") {
    return fmt::format("cheval ase {} [{} when EST has no velocity]{}", common, Flag("EvaluationOptions::pose_only"), stat);
  }
  return fmt::format("cheval rpe {} {}  # {}", common, Flag("EvaluationOptions::kitti_drift"),
                     metric == "kitti_drift_trans" ? "translation %" : "rotation deg/m");
}

std::string Extension(const std::string& path) { return std::filesystem::path(path).extension().string(); }

void Run(const TableFlags& flags) {
  namespace fs = std::filesystem;
  const bool is_folder = fs::is_directory(flags.experiment);
  if (!is_folder && !fs::exists(flags.experiment)) throw InputError(flags.experiment, 0, 0, "no such file or folder");
  table::Experiment e = is_folder
                            ? table::ReadRpgLayout(flags.experiment, flags.rpg ? table::TableMode::kRpg : table::TableMode::kCheval)
                            : table::ReadExperimentConfig(flags.experiment);
  if (flags.rpg && e.mode != table::TableMode::kRpg) {
    e.mode = table::TableMode::kRpg;
    try {
      table::CheckMetrics(e);
    } catch (const UsageError&) {
      e.metrics = table::DefaultMetrics(e.mode);  // the file's metrics are cheval-mode names
    }
  }
  if (is_folder) e.metrics = table::DefaultMetrics(e.mode);
  if (!flags.metrics.empty()) {
    e.metrics.clear();
    std::stringstream s(flags.metrics);
    for (std::string m; std::getline(s, m, ',');) {
      if (!m.empty()) e.metrics.push_back(m);
    }
  }
  table::CheckMetrics(e);

  // Outputs: -o by its extension, plus the explicit ones.
  std::vector<OutputPath> outputs = {{"-o", flags.output},      {"--json", flags.json}, {"--latex", flags.latex},
                                     {"--csv", flags.csv},      {"--html", flags.html}, {"--markdown", flags.markdown}};
  std::vector<std::string> inputs = {flags.experiment};
  for (const auto& run : e.runs) {
    inputs.push_back(run.reference);
    inputs.push_back(run.estimate);
  }
  RefuseSharedPaths(inputs, outputs);

  table::EvaluateRunsOptions options;
  options.threads = flags.jobs;
  if (!flags.no_cache && flags.output != "-") {
    options.cache_folder = (fs::path(flags.output).parent_path() / ".cheval-table-cache").string();
  }
  const auto start = std::chrono::steady_clock::now();
  TerminalProgress& progress = Progress();
  if (progress.enabled()) {
    options.progress = [&progress, start](std::string_view, int64_t done, int64_t total) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double eta = done > 0 ? elapsed / static_cast<double>(done) * static_cast<double>(total - done) : 0;
      progress.Update(fmt::format("runs {}/{}, ETA {:.0f} s", done, total, eta), done, total);
    };
  }
  const std::vector<table::RunResult> results = table::EvaluateRuns(e, options);
  progress.Clear();

  size_t cached = 0, failed = 0;
  for (const auto& r : results) {
    cached += r.from_cache ? 1 : 0;
    failed += r.failure.empty() ? 0 : 1;
  }
  if (failed == results.size()) {
    throw ComputeError(fmt::format("every run failed; the first: {}", results.front().failure));
  }
  table::Table t = table::BuildTable(e, results);
  if (e.mode == table::TableMode::kCheval) {
    for (const std::string& m : e.metrics) t.commands.push_back(Command(e, m));
  }
  const std::string title = flags.title.empty() ? fs::path(flags.experiment).filename().string() : flags.title;
  auto render = [&](const std::string& path, const std::string& fallback) -> std::string {
    std::string ext = Extension(path);
    if (ext.empty()) ext = fallback;
    if (ext == ".json") return table::TableJson(t);
    if (ext == ".tex") return table::TableLatex(t);
    if (ext == ".csv") return table::TableCsv(t);
    if (ext == ".html" || ext == ".htm") return table::TableHtml(t, title);
    return table::TableMarkdown(t);
  };
  std::vector<std::string> texts;
  std::vector<OutputFile> files;
  texts.reserve(6);
  const std::pair<std::string, std::string> all[] = {{flags.output, ".md"}, {flags.json, ".json"},  {flags.latex, ".tex"},
                                                     {flags.csv, ".csv"},   {flags.html, ".html"}, {flags.markdown, ".md"}};
  for (const auto& [path, ext] : all) {
    if (path.empty()) continue;
    texts.push_back(path == flags.output ? render(path, ext) : render(ext == ".md" ? "x.md" : "x" + ext, ext));
    files.push_back({path, texts.back()});
  }
  WriteOutputs(files);
  if (!Quiet()) {
    fmt::print(stderr, "table: {} runs ({} mode): {} evaluated, {} from the cache, {} failed\n", results.size(),
               e.mode == table::TableMode::kRpg ? "rpg" : "cheval", results.size() - cached, cached, failed);
  }
}

}  // namespace

void RegisterTable(CLI::App& app, Action* action) {
  auto flags = std::make_shared<TableFlags>();
  CLI::App* command = app.add_subcommand(
      "table", "Evaluate a whole experiment (rpg_trajectory_evaluation's folder layout or a YAML file) into one table "
               "of statistics over trials: Markdown, LaTeX, CSV, JSON, HTML");
  command->add_option("experiment", flags->experiment, "rpg-layout folder or experiment .yaml file")->required();
  command->add_option("-o,--output", flags->output,
                      "The table; its form from the extension: .md, .tex, .csv, .json, .html (- for Markdown on stdout)")
      ->required();
  command->add_option("--json", flags->json, "Also the table as JSON");
  command->add_option("--latex", flags->latex, "Also the table as LaTeX (booktabs)");
  command->add_option("--csv", flags->csv, "Also the table as CSV");
  command->add_option("--html", flags->html, "Also an HTML page of the experiment");
  command->add_option("--markdown", flags->markdown, "Also the table as Markdown");
  command->add_option("-j,--jobs", flags->jobs, "Runs evaluated in parallel")->check(CLI::Range(1, 256))->capture_default_str();
  command->add_flag("--rpg", flags->rpg,
                    "rpg_trajectory_evaluation's numbers: its association, eval_cfg.yaml alignment and errors");
  command->add_option("--metrics", flags->metrics, "Comma-separated metrics instead of the mode's defaults");
  command->add_flag("--no-cache", flags->no_cache, "Evaluate every run (no per-run cache beside the output)");
  command->add_option("--title", flags->title, "Title of the HTML page (default: the experiment's name)");
  command->callback([flags, action] { *action = [flags] { Run(*flags); }; });
}

}  // namespace cheval::cli

// `cheval report REF EST [EST2 ...] -o report.html`: one self-contained HTML page with the aligned
// trajectories, APE and ASE over time, velocities, the comparison table and the reference's
// Chebyshev fit diagnostics (docs/report.md). The evaluation flags are those of ape/ase.
#include <filesystem>

#include <fmt/format.h>

#include "cheval/report/report.h"
#include "eval_command.h"

namespace cheval::cli {
namespace {

struct ReportFlags {
  EvalFlags eval;
  std::string output;
  report::ReportOptions options;  // max_points bound; the rest set by Run
};

void Run(CLI::App* command, const ReportFlags& flags) {
  // Before any work: a build without the page cannot write one.
  report::RequireReportPage();
  report::ReportOptions options = flags.options;
  options.ape = ToEvaluationOptions(eval::MetricKind::kApe, flags.eval);
  options.ase = ToEvaluationOptions(eval::MetricKind::kAse, flags.eval);
  options.generator = fmt::format("cheval {}", CHEVAL_VERSION);
  options.option_names = FlagNames();  // the notes quote library messages
  options.Validate();
  RefuseSharedPaths(EvalInputPaths(flags.eval), {{"-o", flags.output}});
  const EvalInputs inputs = ReadEvalInputs(command, flags.eval);
  // Ties decided as evo would read the files (OptionsForEstimate). The report takes one set of
  // options: the estimates' formats decide it when they agree (they differ only in a mixed-format
  // report, where the first estimate's reading is used).
  options.ape = OptionsForEstimate(options.ape, inputs, 0);
  options.ase = OptionsForEstimate(options.ase, inputs, 0);
  std::vector<report::ReportInput> estimates;
  for (size_t k = 0; k < inputs.estimates.size(); ++k) {
    // The label: --label's, else empty (the page's own short name, report::ReportInput::label).
    estimates.push_back({inputs.estimate_names[k], inputs.estimates[k].View(),
                         flags.eval.labels.empty() ? std::string() : inputs.estimate_labels[k]});
  }
  const report::Report result =
      report::BuildReport({flags.eval.reference, inputs.reference.View(), ""}, estimates, options);
  const std::string reference_name =
      options.show_paths ? flags.eval.reference : std::filesystem::path(flags.eval.reference).filename().string();
  const std::string page = report::RenderReportHtml(
      result.data_json, fmt::format("cheval report: {} estimate(s) against {}", estimates.size(), reference_name));
  WriteOutput(flags.output, page);

  for (size_t k = 0; k < result.ape.size(); ++k) {
    const eval::EvaluationResult& ape = result.ape[k].result;
    fmt::print("{}: {} pairs, APE {} rmse {:.6f} {}", result.ape[k].estimate_path, ape.association.size(), ape.relation,
               ape.stats.rmse, ape.unit.empty() ? "(unit-less)" : ape.unit);
    if (result.ase[k]) fmt::print(", ASE rmse {:.6f}", result.ase[k]->result.stats.rmse);
    fmt::print("\n");
  }
  for (const std::string& note : result.notes) fmt::print("note: {}\n", note);
  fmt::print("{}: {:.1f} kB\n", flags.output, static_cast<double>(page.size()) / 1000.0);
}

}  // namespace

void RegisterReport(CLI::App& app, Action* action) {
  auto flags = std::make_shared<ReportFlags>();
  // A report compares estimates by eye: unaligned estimates (each in its own start frame) would be
  // drawn and scored apart from the reference, so the report aligns by default, with SE(3) Umeyama
  // as evo users do for metric (stereo / visual-inertial) estimators; --align sim3 for monocular.
  flags->eval.align = "se3";
  CLI::App* command = app.add_subcommand(
      "report",
      "Self-contained HTML report: trajectories, APE and ASE over time, velocities, comparison table, "
      "Chebyshev fit diagnostics");
  AddEvalInputFlags(command, &flags->eval);
  AddRelationFlag(command, &flags->eval);
  AddStateVelocityFlags(command, &flags->eval);
  command->add_option("-o,--output", flags->output, "The HTML file to write")->required();
  command
      ->add_option(Flag("ReportOptions::max_points"), flags->options.max_points,
                   "Most points of one plotted series (min/max buckets over time; the statistics use every pair)")
      ->capture_default_str();
  command->add_flag("--show-paths", flags->options.show_paths,
                    "Show the inputs' file paths in the page (default: their file names only)");
  command->callback([command, flags, action] { *action = [command, flags] { Run(command, *flags); }; });
}

}  // namespace cheval::cli

#pragma once
/// \file
/// The HTML report of `cheval report REF EST [EST2 ...]` (docs/report.md): one self-contained page
/// (chart library, page script, styles and data inlined) with the aligned trajectories, APE and ASE
/// over time, their distributions (histogram, box and violin), the RPE at 10..50 % of the reference's
/// length (over time and as box plots per distance), x/y/z and roll/pitch/yaw over time, the
/// reference velocity (Chebyshev and central differences, and its own columns) against each
/// estimate's, the comparison table, and the diagnostics of the reference's Chebyshev fit. BuildReport computes everything the page shows (the statistics from all pairs; the plotted
/// series decimated, decimate.h); RenderReportHtml writes the page around it.

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cheval/common/option_names.h"
#include "cheval/eval/evaluate.h"
#include "cheval/traj/trajectory.h"

namespace cheval::report {

/// A trajectory of the report. The page names it by its label (legends, table, notes); its path
/// appears in the page only with ReportOptions::show_paths.
struct ReportInput {
  /// The file it was read from.
  std::string path;
  traj::TrajectoryView trajectory;
  /// The short name the page shows; empty: the file name of `path` (with as many parent folders as
  /// tell two estimates of the same file name apart).
  std::string label;
};

/// Options of BuildReport.
struct ReportOptions {
  /// The APE's options (relation, association, alignment); its metric is ignored.
  eval::EvaluationOptions ape;
  /// The ASE's options (reference velocity source, estimate velocity frame, the same association and
  /// alignment); its metric is ignored.
  eval::EvaluationOptions ase;
  /// Most points of one plotted series (min/max buckets for series over time, a stride for paths).
  std::size_t max_points = 5000;
  /// Most windows of the reference's Chebyshev fit whose coefficient magnitudes are embedded (evenly
  /// spread over the windows; the degrees of every window are embedded).
  std::size_t max_fit_windows = 64;
  /// Show the inputs' file paths in the page (header, the embedded results' `path`); otherwise
  /// only labels, so a page shared with others does not carry the machine's folders.
  bool show_paths = false;
  /// Shown in the page's footer, e.g. "cheval 0.1.0".
  std::string generator;
  /// The caller's spelling of option names in the notes, which quote library messages
  /// (common/option_names.h; empty: the library's STRUCT::FIELD names). Must outlive BuildReport.
  std::span<const OptionName> option_names;

  /// Validates ape and ase (EvaluationOptions::Validate) and throws OptionError for max_points < 16
  /// or max_fit_windows < 1.
  void Validate() const;
};

/// What BuildReport computed.
struct Report {
  /// Per estimate, its APE, and its ASE when it has velocity and the ASE can be computed (nullopt
  /// otherwise), from all pairs:
  /// the same results `cheval ape|ase --json` writes with the same options.
  std::vector<eval::EvaluationReport> ape;
  std::vector<std::optional<eval::EvaluationReport>> ase;
  /// Why something is not shown (an estimate without velocity, a reference without stamps, ...).
  std::vector<std::string> notes;
  /// The page's data (JSON, docs/report.md "Embedded data"): version, inputs, options, the APE and
  /// ASE results exactly as `cheval ape|ase --json` writes them, the decimated series, the fit
  /// diagnostics, the notes.
  std::string data_json;
};

/// Evaluates every estimate against the reference (APE; ASE where the estimate has velocity) and
/// gathers the series the page plots. Throws what eval::Evaluate throws for the APE (the errors of
/// `cheval ape`, e.g. ComputeError when no pair is found) and OptionError for bad options
/// (options.Validate()). What can be computed for the charts alone becomes a note instead of an
/// error: an estimate without velocity, an ASE that is impossible where the APE is not (ComputeError,
/// e.g. a reference without stamps to derive its velocity from, or a given reference velocity on a
/// reference without velocity columns), a reference velocity or fit that cannot be computed (no
/// stamps, too few samples).
Report BuildReport(const ReportInput& reference, const std::vector<ReportInput>& estimates,
                   const ReportOptions& options);

/// True when this build embeds the page's chart library (CMake option CHEVAL_BUILD_REPORT).
bool ReportPageAvailable();

/// Throws UsageError naming the CMake option when !ReportPageAvailable() (a caller checks this
/// before any work).
void RequireReportPage();

/// The HTML page around BuildReport's data_json: the chart library's script and styles, the page's
/// own script and styles and the data, all inline; `title` (plain text) is escaped. Throws
/// UsageError when !ReportPageAvailable(), naming the CMake option.
std::string RenderReportHtml(std::string_view data_json, std::string_view title);

}  // namespace cheval::report

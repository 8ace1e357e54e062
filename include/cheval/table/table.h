#pragma once
/// \file
/// Evaluating an experiment's runs (in parallel, with a per-run cache) and the table of statistics
/// over trials in its output forms: Markdown, LaTeX (booktabs), CSV, JSON and an HTML page
/// (docs/table.md).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cheval/common/progress.h"
#include "cheval/table/experiment.h"

namespace cheval::table {

/// The numbers of one run: one value per experiment metric (nullopt when that metric failed), or
/// a run-level failure.
struct RunResult {
  std::vector<std::optional<double>> values;
  /// Per metric: why it failed (empty when it has a value).
  std::vector<std::string> errors;
  /// Why the whole run failed (missing or unreadable file, nothing associated), else empty.
  std::string failure;
  bool from_cache = false;
};

/// Options of EvaluateRuns.
struct EvaluateRunsOptions {
  /// Worker threads (>= 1); runs are independent.
  int threads = 1;
  /// Folder of the per-run cache (created when missing), empty for none. Each run's numbers are
  /// stored under a hash of the reference's and estimate's contents, the mode, the run's
  /// alignment, the metrics and the options, so a run is evaluated again only when one of them changes.
  std::string cache_folder;
  /// Called with ("runs", done, total) as runs finish (from the worker threads, serialised).
  ProgressFn progress;
};

/// Evaluates every run. A run that fails (a missing file, bad input, nothing to associate) is
/// recorded as failed, not thrown; OutputError only for a cache file that cannot be written.
/// The reference of a sequence is read once and, in cheval mode, its Chebyshev velocity (ASE of
/// estimates with velocity) fitted once and shared by all runs on it.
std::vector<RunResult> EvaluateRuns(const Experiment& experiment, const EvaluateRunsOptions& options = {});

/// One row of the table: an algorithm on a dataset, one metric, over its trials.
struct TableRow {
  std::string algorithm, dataset, metric, unit;
  std::vector<std::optional<double>> trials;  ///< trial order; nullopt for a failed trial
  std::optional<double> mean, std, median;    ///< over the successful trials (std: population)
  int failed = 0;
  bool best = false;  ///< lowest mean among the algorithms on this dataset and metric
  std::vector<std::string> failures;  ///< "trial N: reason" per failed trial
};

/// The table of an experiment and its run results.
struct Table {
  TableMode mode = TableMode::kCheval;
  std::vector<std::string> algorithms, datasets, metrics;
  std::vector<TableRow> rows;  ///< per algorithm, dataset, metric in that order
  /// The `cheval` command that gives each cheval-mode metric of a run by hand (REF and EST
  /// standing for the files), keyed like `metrics`.
  std::vector<std::string> commands;
};

/// Builds the table: per row the trial values, mean ± std, median, failed count, best marks.
Table BuildTable(const Experiment& experiment, const std::vector<RunResult>& results);

/// The unit of a metric ("m", "deg", "%", "deg/m", "" for the unit-less ASE).
std::string MetricUnit(const std::string& metric);

/// Markdown: one line per algorithm and dataset, one column per metric, "mean ± std" with the best
/// in bold, failed trials as "(k failed)"; a legend line below.
std::string TableMarkdown(const Table& table);
/// LaTeX with booktabs (\toprule, \midrule, \bottomrule), best in \textbf; a complete tabular.
std::string TableLatex(const Table& table);
/// CSV (RFC 4180): algorithm,dataset,metric,unit,mean,std,median,failed,best,trial_0..trial_{n-1}.
std::string TableCsv(const Table& table);
/// JSON: {"mode", "metrics", "commands", "rows": [{algorithm, dataset, metric, unit, trials, mean,
/// std, median, failed, best}]}; null for missing numbers. 2-space indentation, final newline.
std::string TableJson(const Table& table);
/// A self-contained HTML page: the table per dataset, per-trial values, failures, the commands.
std::string TableHtml(const Table& table, const std::string& title);

}  // namespace cheval::table

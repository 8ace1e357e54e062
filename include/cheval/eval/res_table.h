#pragma once
/// \file
/// The statistics table of `cheval res` (evo_res's): one row per result, one column per statistic,
/// as evo_res prints it (pandas' `DataFrame.to_string(line_width=80)` with evo's display options) and
/// as Markdown, LaTeX (booktabs) or CSV. docs/cli.md, "cheval res".

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cheval/eval/res_read.h"

namespace cheval::eval {

/// How the rows are named.
struct ResTableOptions {
  /// One name per result, in order (empty: evo's default, the base name of info's est_name).
  std::vector<std::string> labels;
  /// Name each row by its file's path as given (evo_res --use_filenames); ignored when labels are given.
  bool use_filenames = false;
};

/// The table of several results.
struct ResTable {
  /// The first result's title (info "title"; empty for cheval JSON).
  std::string title;
  std::vector<std::string> labels;
  /// Statistic names: the first result's stats.json order, then any further names as they appear.
  std::vector<std::string> columns;
  /// values[row][column]; nullopt where a result has no such statistic.
  std::vector<std::vector<std::optional<double>>> values;
  /// Results whose title differs from the first one's (evo_res warns about them): "PATH: TITLE".
  std::vector<std::string> title_conflicts;
};

/// The table of `results`. UsageError when the labels given are not one per result, or when two rows
/// get the same name (evo_res refuses duplicate est_name values too).
ResTable BuildResTable(const std::vector<ResultFile>& results, const ResTableOptions& options);

/// The table as evo_res prints it: pandas' object-column layout (each value as `{: .6f}` with trailing
/// zeros trimmed, NaN where missing; names left-aligned and cut to 17 characters + "..." beyond 20;
/// values right-aligned; columns wrapped into blocks at 80 characters with " \" ending each
/// block but the last).
std::string EvoResText(const ResTable& table);

/// The table as a Markdown pipe table, every number in its shortest round-trip form.
std::string ResTableMarkdown(const ResTable& table);
/// The table as a LaTeX booktabs tabular (names escaped), numbers in shortest round-trip form.
std::string ResTableLatex(const ResTable& table);
/// The table as CSV (RFC 4180), pandas' `to_csv` layout: an empty first header cell, then the
/// statistics; numbers in shortest round-trip form (Python's repr), empty where missing.
std::string ResTableCsv(const ResTable& table);

/// A text field of a CSV row as RFC 4180 has it: in double quotes, inner quotes doubled, when it holds
/// a comma, a quote, a CR or a LF (a file name may); as it is otherwise.
std::string CsvField(std::string_view text);

}  // namespace cheval::eval

#include "cheval/eval/res_table.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::eval {
namespace {

constexpr size_t kMaxColumnWidth = 20;  // evo_res: pd.options.display.max_colwidth = 20
constexpr size_t kLineWidth = 80;       // evo_res: to_string(line_width=80)

// pandas' object-column float: f"{x: .6f}" with trailing zeros trimmed (one kept after the point).
std::string PandasFloat(const std::optional<double>& v) {
  if (!v || std::isnan(*v)) return " NaN";
  std::string s = fmt::format("{: .6f}", *v);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s += '0';
  }
  return s;
}

// pandas' _make_fixed_width: cut what is longer than the column limit to 17 characters + "...".
std::string Cut(const std::string& s) {
  return s.size() > kMaxColumnWidth ? s.substr(0, kMaxColumnWidth - 3) + "..." : s;
}

std::string Pad(const std::string& s, size_t width, bool left) {
  if (s.size() >= width) return s;
  return left ? s + std::string(width - s.size(), ' ') : std::string(width - s.size(), ' ') + s;
}

// Python's repr of a float: the shortest text that reads back to it, with ".0" on whole numbers.
std::string Repr(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

// Each statistic of each row, in the given form; `missing` where a result has none.
template <typename Format>
std::vector<std::vector<std::string>> Cells(const ResTable& t, Format format, const std::string& missing) {
  std::vector<std::vector<std::string>> cells(t.values.size());
  for (size_t r = 0; r < t.values.size(); ++r) {
    for (const auto& v : t.values[r]) cells[r].push_back(v ? format(*v) : missing);
  }
  return cells;
}

// The header row (an empty first cell, then the statistics), `after_header`, then one row per result:
// cells joined by `separator`, names through `escape`, each row ended by `end`.
std::string Rows(const ResTable& t, const std::vector<std::vector<std::string>>& cells,
                 std::string (*escape)(std::string_view), std::string_view separator, std::string_view end,
                 std::string_view after_header) {
  std::string out;
  for (const std::string& c : t.columns) out += fmt::format("{}{}", separator, escape(c));
  out += fmt::format("{}{}", end, after_header);
  for (size_t r = 0; r < cells.size(); ++r) {
    out += escape(t.labels[r]);
    for (const std::string& v : cells[r]) out += fmt::format("{}{}", separator, v);
    out += end;
  }
  return out;
}

std::string LatexEscape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '\\': out += "\\textbackslash{}"; break;
      case '~': out += "\\textasciitilde{}"; break;
      case '^': out += "\\textasciicircum{}"; break;
      case '&': case '%': case '$': case '#': case '_': case '{': case '}': out += '\\'; out += c; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

std::string CsvField(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

ResTable BuildResTable(const std::vector<ResultFile>& results, const ResTableOptions& options) {
  if (!options.labels.empty() && options.labels.size() != results.size()) {
    throw UsageError(fmt::format("{} labels for {} results: give one per result, in order", options.labels.size(),
                                 results.size()));
  }
  ResTable t;
  if (results.empty()) return t;
  t.title = results.front().Info("title");
  for (size_t k = 0; k < results.size(); ++k) {
    const ResultFile& r = results[k];
    std::string label = !options.labels.empty() ? options.labels[k] : options.use_filenames ? r.path : "";
    if (label.empty()) {
      const std::string est = r.Info("est_name");
      label = est.empty() ? "unnamed_result" : std::filesystem::path(est).filename().string();
    }
    t.labels.push_back(label);
    if (k > 0 && r.Info("title") != t.title) t.title_conflicts.push_back(fmt::format("{}: {}", r.path, r.Info("title")));
    for (const auto& [name, value] : r.stats) {
      if (std::find(t.columns.begin(), t.columns.end(), name) == t.columns.end()) t.columns.push_back(name);
    }
  }
  for (size_t k = 0; k < t.labels.size(); ++k) {
    for (size_t j = 0; j < k; ++j) {
      if (t.labels[j] == t.labels[k]) {
        throw UsageError(fmt::format("two results are named \"{}\" ({} and {}): name them with --label, or by their "
                                     "file names with --use-filenames", t.labels[k], results[j].path, results[k].path));
      }
    }
  }
  for (const ResultFile& r : results) {
    std::vector<std::optional<double>> row(t.columns.size());
    for (const auto& [name, value] : r.stats) {
      row[static_cast<size_t>(std::find(t.columns.begin(), t.columns.end(), name) - t.columns.begin())] = value;
    }
    t.values.push_back(std::move(row));
  }
  return t;
}

std::string EvoResText(const ResTable& t) {
  // The index column: an empty header, the names left-aligned (cut beyond 20 characters).
  std::vector<std::string> index = {""};
  size_t index_width = 0;
  for (const std::string& label : t.labels) index_width = std::max(index_width, std::min(label.size(), kMaxColumnWidth));
  for (const std::string& label : t.labels) index.push_back(Pad(Cut(label), index_width, true));
  // One column per statistic: the header and the values right-aligned to the widest.
  std::vector<std::vector<std::string>> columns;
  std::vector<size_t> widths;
  for (size_t c = 0; c < t.columns.size(); ++c) {
    std::vector<std::string> values;
    size_t value_width = 0;
    for (const auto& row : t.values) {
      values.push_back(PandasFloat(row[c]));
      value_width = std::max(value_width, values.back().size());
    }
    size_t width = std::min(std::max(value_width, t.columns[c].size()), kMaxColumnWidth);
    for (std::string& v : values) v = Pad(Cut(v), width, false);
    width = std::max(width, t.columns[c].size());
    std::vector<std::string> column = {Pad(t.columns[c], width, false)};
    for (std::string& v : values) column.push_back(Pad(v, width, false));
    columns.push_back(std::move(column));
    widths.push_back(width);
  }
  // pandas' _binify: blocks of columns that fit in the line width beside the index.
  const size_t available = kLineWidth - std::min(kLineWidth, index_width + 1);
  std::vector<size_t> ends;
  size_t current = 0;
  for (size_t c = 0; c < widths.size(); ++c) {
    current += widths[c] + 1;
    const bool last = c + 1 == widths.size();
    if (c > 0 && current + (last ? 1 : 2) > available) {
      ends.push_back(c);
      current = widths[c] + 1;
    }
  }
  ends.push_back(widths.size());
  // pandas' adjoin: every column but the last padded to its width + 1.
  const size_t rows = t.labels.size() + 1;
  std::string out;
  size_t start = 0;
  for (size_t b = 0; b < ends.size(); ++b) {
    std::vector<std::vector<std::string>> block = {index};
    for (size_t c = start; c < ends[b]; ++c) block.push_back(columns[c]);
    if (ends.size() > 1) {
      std::vector<std::string> marker(rows, b + 1 < ends.size() ? "  " : " ");
      if (b + 1 < ends.size()) marker[0] = " \\";
      block.push_back(marker);
    }
    if (b > 0) out += "\n\n";
    for (size_t r = 0; r < rows; ++r) {
      if (r > 0) out += '\n';
      for (size_t c = 0; c < block.size(); ++c) {
        size_t width = 0;
        for (const std::string& s : block[c]) width = std::max(width, s.size());
        out += Pad(block[c][r], c + 1 < block.size() ? width + 1 : width, true);
      }
    }
    start = ends[b];
  }
  return out;
}

std::string ResTableMarkdown(const ResTable& t) {
  const auto cells = Cells(t, Repr, "");
  std::string out = "| |";
  for (const std::string& c : t.columns) out += fmt::format(" {} |", c);
  out += "\n|:--|";
  for (size_t c = 0; c < t.columns.size(); ++c) out += "--:|";
  out += '\n';
  for (size_t r = 0; r < cells.size(); ++r) {
    std::string label;
    for (char ch : t.labels[r]) label += ch == '|' ? std::string("\\|") : std::string(1, ch);
    out += fmt::format("| {} |", label);
    for (const std::string& v : cells[r]) out += fmt::format(" {} |", v);
    out += '\n';
  }
  return out;
}

std::string ResTableLatex(const ResTable& t) {
  return fmt::format("\\begin{{tabular}}{{l{}}}\n\\toprule\n", std::string(t.columns.size(), 'r')) +
         Rows(t, Cells(t, Repr, "--"), LatexEscape, " & ", " \\\\\n", "\\midrule\n") + "\\bottomrule\n\\end{tabular}\n";
}

std::string ResTableCsv(const ResTable& t) { return Rows(t, Cells(t, Repr, ""), CsvField, ",", "\n", ""); }

}  // namespace cheval::eval

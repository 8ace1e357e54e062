// The table's output forms: Markdown, LaTeX (booktabs), CSV, JSON, HTML (cheval/table/table.h).
#include <functional>
#include <regex>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cheval/table/table.h"

namespace cheval::table {
namespace {

// "APE trans. (m)", "RPE rot. 10 m (deg)", "RPE trans. 20 % (m)", "ASE".
std::string MetricTitle(const std::string& metric) {
  static const std::regex rpe(R"(rpe_(trans|rot)_([0-9.]+)(m|pct))");
  std::smatch m;
  std::string title;
  if (metric == "ape_trans") title = "APE trans.";
  else if (metric == "ape_rot") title = "APE rot.";
  else if (metric == "ase") title = "ASE";
  else if (metric == "kitti_drift_trans") title = "KITTI drift trans.";
  else if (metric == "kitti_drift_rot") title = "KITTI drift rot.";
  else if (std::regex_match(metric, m, rpe)) {
    title = fmt::format("RPE {}. {} {}", m[1].str(), m[2].str(), m[3] == "m" ? "m" : "%");
  } else {
    title = metric;
  }
  const std::string unit = MetricUnit(metric);
  return unit.empty() ? title : fmt::format("{} ({})", title, unit);
}

std::string Number(double v) { return fmt::format("{:.4g}", v); }

// The row of (algorithm, dataset, metric), or nullptr.
const TableRow* Find(const Table& t, const std::string& a, const std::string& d, const std::string& m) {
  for (const TableRow& r : t.rows) {
    if (r.algorithm == a && r.dataset == d && r.metric == m) return &r;
  }
  return nullptr;
}

// One cell: "mean ± std" (pm given), "(k failed)" appended, "–" when no trial succeeded; `bold` wraps the best.
std::string Cell(const TableRow* r, const std::string& pm, const std::function<std::string(const std::string&)>& bold,
                 const std::string& failed_word) {
  if (r == nullptr) return "";
  std::string s;
  if (!r->mean) {
    s = "–";
  } else {
    s = r->trials.size() > 1 ? Number(*r->mean) + pm + Number(*r->std) : Number(*r->mean);
    if (r->best) s = bold(s);
  }
  if (r->failed > 0) s += fmt::format(" ({} {})", r->failed, failed_word);
  return s;
}

std::string LatexEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '_' || c == '%' || c == '&' || c == '#' || c == '$' || c == '{' || c == '}') out += '\\';
    out += c;
  }
  return out;
}

std::string HtmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string Shortest(double v) { return nlohmann::json(v).dump(); }

}  // namespace

std::string TableMarkdown(const Table& t) {
  std::string out = "| Algorithm | Dataset |";
  std::string rule = "|---|---|";
  for (const std::string& m : t.metrics) {
    out += " " + MetricTitle(m) + " |";
    rule += "---:|";
  }
  out += "\n" + rule + "\n";
  for (const std::string& a : t.algorithms) {
    for (const std::string& d : t.datasets) {
      if (!Find(t, a, d, t.metrics.front())) continue;
      out += fmt::format("| {} | {} |", a, d);
      for (const std::string& m : t.metrics) {
        out += " " + Cell(Find(t, a, d, m), " ± ", [](const std::string& s) { return "**" + s + "**"; }, "failed") + " |";
      }
      out += "\n";
    }
  }
  out += fmt::format("\nMean ± std over trials ({} mode); **bold**: lowest mean on the dataset; \"k failed\": trials "
                     "without a value.\n",
                     t.mode == TableMode::kRpg ? "rpg" : "cheval");
  out += "\n### Per trial\n\n| Algorithm | Dataset | Metric | Median | Trials | Failed |\n|---|---|---|---:|---|---:|\n";
  for (const TableRow& r : t.rows) {
    std::vector<std::string> v;
    for (const auto& x : r.trials) v.push_back(x ? Number(*x) : "failed");
    out += fmt::format("| {} | {} | {} | {} | {} | {} |\n", r.algorithm, r.dataset, r.metric,
                       r.median ? Number(*r.median) : "–", fmt::join(v, ", "), r.failed);
  }
  bool any = false;
  for (const TableRow& r : t.rows) {
    for (const std::string& f : r.failures) {
      if (!any) out += "\n### Failures\n\n";
      any = true;
      out += fmt::format("- {} / {} / {}: {}\n", r.algorithm, r.dataset, r.metric, f);
    }
  }
  return out;
}

std::string TableLatex(const Table& t) {
  std::string out = "% cheval table; needs \\usepackage{booktabs}\n\\begin{tabular}{ll";
  for (size_t k = 0; k < t.metrics.size(); ++k) out += "r";
  out += "}\n\\toprule\nAlgorithm & Dataset";
  for (const std::string& m : t.metrics) out += " & " + LatexEscape(MetricTitle(m));
  out += " \\\\\n\\midrule\n";
  for (const std::string& a : t.algorithms) {
    for (const std::string& d : t.datasets) {
      if (!Find(t, a, d, t.metrics.front())) continue;
      out += LatexEscape(a) + " & " + LatexEscape(d);
      for (const std::string& m : t.metrics) {
        std::string cell = Cell(Find(t, a, d, m), " $\\pm$ ", [](const std::string& s) { return "\\textbf{" + s + "}"; },
                                "failed");
        if (cell.starts_with("–")) cell = "--" + cell.substr(std::string("–").size());
        out += " & " + cell;
      }
      out += " \\\\\n";
    }
  }
  out += "\\bottomrule\n\\end{tabular}\n";
  return out;
}

std::string TableCsv(const Table& t) {
  size_t n = 0;
  for (const TableRow& r : t.rows) n = std::max(n, r.trials.size());
  std::string out = "algorithm,dataset,metric,unit,mean,std,median,failed,best";
  for (size_t k = 0; k < n; ++k) out += fmt::format(",trial_{}", k);
  out += "\n";
  auto opt = [](const std::optional<double>& v) { return v ? Shortest(*v) : std::string(); };
  for (const TableRow& r : t.rows) {
    out += fmt::format("{},{},{},{},{},{},{},{},{}", CsvField(r.algorithm), CsvField(r.dataset), r.metric, r.unit,
                       opt(r.mean), opt(r.std), opt(r.median), r.failed, r.best ? "true" : "false");
    for (size_t k = 0; k < n; ++k) out += "," + (k < r.trials.size() ? opt(r.trials[k]) : std::string());
    out += "\n";
  }
  return out;
}

std::string TableJson(const Table& t) {
  nlohmann::ordered_json j;
  j["mode"] = t.mode == TableMode::kRpg ? "rpg" : "cheval";
  j["metrics"] = t.metrics;
  j["commands"] = nlohmann::ordered_json::object();
  for (size_t k = 0; k < t.commands.size() && k < t.metrics.size(); ++k) j["commands"][t.metrics[k]] = t.commands[k];
  j["rows"] = nlohmann::ordered_json::array();
  auto opt = [](const std::optional<double>& v) { return v ? nlohmann::ordered_json(*v) : nlohmann::ordered_json(); };
  for (const TableRow& r : t.rows) {
    nlohmann::ordered_json row;
    row["algorithm"] = r.algorithm;
    row["dataset"] = r.dataset;
    row["metric"] = r.metric;
    row["unit"] = r.unit;
    row["trials"] = nlohmann::ordered_json::array();
    for (const auto& v : r.trials) row["trials"].push_back(opt(v));
    row["mean"] = opt(r.mean);
    row["std"] = opt(r.std);
    row["median"] = opt(r.median);
    row["failed"] = r.failed;
    row["best"] = r.best;
    row["failures"] = r.failures;
    j["rows"].push_back(row);
  }
  return j.dump(2) + "\n";
}

std::string TableHtml(const Table& t, const std::string& title) {
  std::string out = fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<link rel=\"icon\" href=\"data:,\">\n<title>{0}</title>\n<style>\n"
      "body{{font-family:system-ui,sans-serif;margin:2em;color:#222}}table{{border-collapse:collapse;margin:1em 0}}"
      "th,td{{padding:.3em .8em;border-bottom:1px solid #ccc;text-align:right}}td{{white-space:nowrap}}th:first-child,td:first-child,"
      "th:nth-child(2),td:nth-child(2){{text-align:left}}thead th{{border-bottom:2px solid #222}}td.best{{font-weight:"
      "bold}}.failed{{color:#b00}}code{{background:#f4f4f4;padding:0 .2em}}\n</style>\n</head>\n<body>\n<h1>{0}</h1>\n"
      "<p>Mean ± std over trials ({1} mode); bold: lowest mean on the dataset.</p>\n",
      HtmlEscape(title), t.mode == TableMode::kRpg ? "rpg" : "cheval");
  for (const std::string& d : t.datasets) {
    out += fmt::format("<h2>{}</h2>\n<table>\n<thead><tr><th>Algorithm</th><th>Trials</th>", HtmlEscape(d));
    for (const std::string& m : t.metrics) out += "<th>" + HtmlEscape(MetricTitle(m)) + "</th>";
    out += "</tr></thead>\n<tbody>\n";
    for (const std::string& a : t.algorithms) {
      const TableRow* first = Find(t, a, d, t.metrics.front());
      if (!first) continue;
      out += fmt::format("<tr><td>{}</td><td>{}</td>", HtmlEscape(a), first->trials.size());
      for (const std::string& m : t.metrics) {
        const TableRow* r = Find(t, a, d, m);
        std::vector<std::string> v;
        for (const auto& x : r->trials) v.push_back(x ? Number(*x) : "failed");
        out += fmt::format("<td{} title=\"median {}; trials: {}\">{}</td>", r->best ? " class=\"best\"" : "",
                           r->median ? Number(*r->median) : "–", HtmlEscape(fmt::format("{}", fmt::join(v, ", "))),
                           HtmlEscape(Cell(r, " ± ", [](const std::string& s) { return s; }, "failed")));
      }
      out += "</tr>\n";
    }
    out += "</tbody>\n</table>\n";
  }
  out += "<h2>Per trial</h2>\n<table>\n<thead><tr><th>Algorithm</th><th>Dataset</th><th>Metric</th><th>Median</th>"
         "<th>Trials</th></tr></thead>\n<tbody>\n";
  for (const TableRow& r : t.rows) {
    std::vector<std::string> v;
    for (const auto& x : r.trials) v.push_back(x ? Number(*x) : "<span class=\"failed\">failed</span>");
    out += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n", HtmlEscape(r.algorithm),
                       HtmlEscape(r.dataset), HtmlEscape(r.metric), r.median ? Number(*r.median) : "–",
                       fmt::format("{}", fmt::join(v, ", ")));
  }
  out += "</tbody>\n</table>\n";
  bool any = false;
  for (const TableRow& r : t.rows) {
    for (const std::string& f : r.failures) {
      if (!any) out += "<h2>Failures</h2>\n<ul>\n";
      any = true;
      out += fmt::format("<li class=\"failed\">{} / {} / {}: {}</li>\n", HtmlEscape(r.algorithm), HtmlEscape(r.dataset),
                         HtmlEscape(r.metric), HtmlEscape(f));
    }
  }
  if (any) out += "</ul>\n";
  if (!t.commands.empty()) {
    out += "<h2>Commands</h2>\n<p>Each cheval-mode number of a run by hand (REF, EST: its files):</p>\n<ul>\n";
    for (size_t k = 0; k < t.commands.size() && k < t.metrics.size(); ++k) {
      out += fmt::format("<li>{}: <code>{}</code></li>\n", HtmlEscape(t.metrics[k]), HtmlEscape(t.commands[k]));
    }
    out += "</ul>\n";
  }
  out += "</body>\n</html>\n";
  return out;
}

}  // namespace cheval::table

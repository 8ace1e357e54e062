// The table of an experiment: statistics over trials and best marks (cheval/table/table.h).
#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "cheval/table/table.h"

namespace cheval::table {

std::string MetricUnit(const std::string& metric) {
  if (metric == "ase") return "";
  if (metric == "kitti_drift_trans") return "%";
  if (metric == "kitti_drift_rot") return "deg/m";
  if (metric.find("_rot") != std::string::npos) return "deg";
  return "m";
}

Table BuildTable(const Experiment& experiment, const std::vector<RunResult>& results) {
  Table table;
  table.mode = experiment.mode;
  table.metrics = experiment.metrics;
  auto add_unique = [](std::vector<std::string>& list, const std::string& v) {
    if (std::find(list.begin(), list.end(), v) == list.end()) list.push_back(v);
  };
  for (const RunSpec& run : experiment.runs) {
    add_unique(table.algorithms, run.algorithm);
    add_unique(table.datasets, run.dataset);
  }
  for (const std::string& algorithm : table.algorithms) {
    for (const std::string& dataset : table.datasets) {
      std::vector<size_t> runs;
      int trials = 0;
      for (size_t i = 0; i < experiment.runs.size(); ++i) {
        const RunSpec& run = experiment.runs[i];
        if (run.algorithm != algorithm || run.dataset != dataset) continue;
        runs.push_back(i);
        trials = std::max(trials, run.trial + 1);
      }
      if (runs.empty()) continue;
      for (size_t k = 0; k < experiment.metrics.size(); ++k) {
        TableRow row;
        row.algorithm = algorithm;
        row.dataset = dataset;
        row.metric = experiment.metrics[k];
        row.unit = MetricUnit(row.metric);
        row.trials.assign(static_cast<size_t>(trials), std::nullopt);
        std::vector<std::string> reasons(static_cast<size_t>(trials), "no run");
        for (size_t i : runs) {
          const RunResult& r = results[i];
          const auto t = static_cast<size_t>(experiment.runs[i].trial);
          if (k < r.values.size() && r.values[k]) {
            row.trials[t] = r.values[k];
          } else {
            reasons[t] = !r.failure.empty() ? r.failure : (k < r.errors.size() ? r.errors[k] : "failed");
          }
        }
        std::vector<double> ok;
        for (size_t t = 0; t < row.trials.size(); ++t) {
          if (row.trials[t]) {
            ok.push_back(*row.trials[t]);
          } else {
            ++row.failed;
            row.failures.push_back(fmt::format("trial {}: {}", t, reasons[t]));
          }
        }
        if (!ok.empty()) {
          double sum = 0;
          for (double v : ok) sum += v;
          const double mean = sum / static_cast<double>(ok.size());
          double var = 0;
          for (double v : ok) var += (v - mean) * (v - mean);
          row.mean = mean;
          row.std = std::sqrt(var / static_cast<double>(ok.size()));
          std::sort(ok.begin(), ok.end());
          const size_t h = ok.size() / 2;
          row.median = ok.size() % 2 ? ok[h] : (ok[h - 1] + ok[h]) / 2;
        }
        table.rows.push_back(std::move(row));
      }
    }
  }
  // Best: the lowest mean per dataset and metric, when at least two algorithms have one.
  std::map<std::pair<std::string, std::string>, std::vector<TableRow*>> groups;
  for (TableRow& row : table.rows) {
    if (row.mean) groups[{row.dataset, row.metric}].push_back(&row);
  }
  for (auto& [key, rows] : groups) {
    if (rows.size() < 2) continue;
    double best = *rows.front()->mean;
    for (const TableRow* r : rows) best = std::min(best, *r->mean);
    for (TableRow* r : rows) r->best = *r->mean == best;
  }
  return table;
}

}  // namespace cheval::table

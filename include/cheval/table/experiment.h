#pragma once
/// \file
/// An experiment: runs (algorithm × dataset × trial, each a reference and an estimate file) and the
/// metrics to tabulate (docs/table.md). Read from rpg_trajectory_evaluation's folder layout or from a
/// small YAML file.

#include <optional>
#include <string>
#include <vector>

#include "cheval/table/rpg.h"

namespace cheval::table {

/// How the numbers are computed.
enum class TableMode {
  kCheval,  ///< cheval's Evaluate: evo's association and metrics (the numbers of `cheval ape/rpe/ase`)
  kRpg,     ///< rpg_trajectory_evaluation's association, alignment and errors (rpg.h)
};

/// One run: an estimate file of one trial of one algorithm on one dataset.
struct RunSpec {
  std::string algorithm;  ///< label as shown in the table
  std::string dataset;    ///< label as shown in the table
  int trial = 0;          ///< 0-based trial number (order of the per-trial values)
  std::string reference;  ///< ground-truth file; empty when none was found (the run fails)
  std::string estimate;   ///< estimate file; empty when the trial is missing (the run fails)
  std::string folder;     ///< rpg layout: the run's folder (eval_cfg.yaml), else empty
  /// Alignment: cheval's method name (none, se3, sim3, posyaw, ...) and frame count (-1 = all).
  std::string align = "se3";
  int align_frames = -1;
  /// rpg mode: the folder's eval_cfg.yaml / start_end_time.yaml.
  RpgEvalConfig rpg;
  /// Why the run cannot be evaluated before any work (missing file), shown as its failure.
  std::string missing;
};

/// The experiment: runs in table order and the metrics (columns).
struct Experiment {
  TableMode mode = TableMode::kCheval;
  std::vector<RunSpec> runs;
  /// Metric names (docs/table.md): ape_trans, ape_rot, rpe_trans_<D>m, rpe_rot_<D>m, ase,
  /// kitti_drift_trans, kitti_drift_rot (cheval mode); ape_trans, ape_rot, rpe_trans_<P>pct,
  /// rpe_rot_<P>pct (rpg mode, P in 10..50).
  std::vector<std::string> metrics;
  /// Statistic of a run's per-pair errors in cheval mode: "rmse" (default), "mean" or "median".
  std::string statistic = "rmse";
  /// Association tolerance in cheval mode (seconds; cheval's default 0.01).
  double max_diff_s = 0.01;
};

/// The default metrics of a mode.
std::vector<std::string> DefaultMetrics(TableMode mode);

/// Whether `path` is a folder in rpg's layout: some `<platform>/<alg>/<platform>_<alg>_<dataset>/`
/// holds a `stamped_traj_estimate*.txt` or `stamped_ba_estimate*.txt`.
bool IsRpgLayout(const std::string& path);

/// Discovers the runs of rpg's layout under `root` (see docs/table.md): per run folder the trials
/// `stamped_traj_estimate.txt` or `stamped_traj_estimate{N}.txt` (algorithm `<alg>`) and
/// `stamped_ba_estimate{N}.txt` (algorithm `<alg>`, or `<alg>/ba` in a folder that also holds
/// `stamped_traj_estimate*`); a missing number below the largest is a
/// failed trial. The reference is the folder's `stamped_groundtruth.txt`, else that of another
/// algorithm's folder of the same platform and dataset. The alignment is read from eval_cfg.yaml.
/// InputError when nothing is found.
Experiment ReadRpgLayout(const std::string& root, TableMode mode);

/// Reads an experiment file (YAML, docs/table.md "Config"): `mode`, `metrics`, `statistic`,
/// `max_diff`, `align`, `align_frames`, `rpg_root`, `datasets` (name → reference, label) and
/// `algorithms` (list of name, label, estimates: dataset → list of files). Paths are relative to the
/// file's folder. InputError naming the file, line and key for anything malformed.
Experiment ReadExperimentConfig(const std::string& path);

/// Throws UsageError naming the first metric that the experiment's mode does not know.
void CheckMetrics(const Experiment& experiment);

}  // namespace cheval::table

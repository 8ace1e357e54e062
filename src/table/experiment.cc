// Experiments from rpg's folder layout or from a YAML file (cheval/table/experiment.h).
#include "cheval/table/experiment.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <regex>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "cheval/common/error.h"
#include "cheval/eval/align.h"

namespace cheval::table {
namespace fs = std::filesystem;
namespace {

// The estimate files of a run folder: (est_type suffix, trial -> file), trial -1 for the unnumbered file.
struct FolderTrials {
  std::map<int, std::string> traj, ba;
};

FolderTrials ListTrials(const fs::path& folder) {
  static const std::regex pattern(R"(stamped_(traj|ba)_estimate(\d*)\.txt)");
  FolderTrials trials;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file(ec) || !std::regex_match(name, m, pattern)) continue;
    const int trial = m[2].length() == 0 ? -1 : (m[2].length() > 6 ? -2 : std::stoi(m[2].str()));
    if (trial == -2) continue;
    (m[1] == "traj" ? trials.traj : trials.ba)[trial] = entry.path().string();
  }
  return trials;
}

// Run folders below root (depth-limited walk), sorted.
std::vector<fs::path> RunFolders(const fs::path& root) {
  std::vector<fs::path> folders;
  std::error_code ec;
  auto consider = [&](const fs::path& p) {
    const FolderTrials t = ListTrials(p);
    if (!t.traj.empty() || !t.ba.empty()) folders.push_back(p);
  };
  consider(root);
  for (auto it = fs::recursive_directory_iterator(root, fs::directory_options::skip_permission_denied, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    if (it.depth() >= 6) it.disable_recursion_pending();
    if (it->is_directory(ec) && it->path().filename() != "saved_results") consider(it->path());
  }
  std::sort(folders.begin(), folders.end());
  return folders;
}

// The ground truth of a run folder: its own, else another algorithm's folder of the same platform
// and dataset (rpg's examples keep one copy per dataset).
std::string FindReference(const fs::path& folder, const std::string& platform, const std::string& dataset) {
  const fs::path own = folder / "stamped_groundtruth.txt";
  if (fs::is_regular_file(own)) return own.string();
  const fs::path platform_dir = folder.parent_path().parent_path();
  std::vector<fs::path> candidates;
  std::error_code ec;
  for (const auto& alg : fs::directory_iterator(platform_dir, ec)) {
    if (!alg.is_directory(ec)) continue;
    for (const auto& run : fs::directory_iterator(alg.path(), ec)) {
      const std::string name = run.path().filename().string();
      const std::string prefix = platform + "_", suffix = "_" + dataset;
      if (name.size() > prefix.size() + suffix.size() && name.starts_with(prefix) && name.ends_with(suffix) &&
          fs::is_regular_file(run.path() / "stamped_groundtruth.txt")) {
        candidates.push_back(run.path() / "stamped_groundtruth.txt");
      }
    }
  }
  std::sort(candidates.begin(), candidates.end());
  return candidates.empty() ? std::string() : candidates.front().string();
}

std::string ChevalAlign(const std::string& rpg_type) { return rpg_type; }  // same names: posyaw, sim3, se3, none

void AddTrials(Experiment* e, const std::map<int, std::string>& trials, const RunSpec& base) {
  if (trials.empty()) return;
  if (trials.count(-1) && trials.size() == 1) {
    RunSpec run = base;
    run.estimate = trials.at(-1);
    e->runs.push_back(run);
    return;
  }
  const int last = trials.rbegin()->first;
  for (int k = 0; k <= last; ++k) {
    RunSpec run = base;
    run.trial = k;
    if (auto it = trials.find(k); it != trials.end()) {
      run.estimate = it->second;
    } else {
      run.missing = fmt::format("no estimate file for trial {} in {}", k, base.folder);
    }
    e->runs.push_back(run);
  }
}

}  // namespace

std::vector<std::string> DefaultMetrics(TableMode mode) {
  if (mode == TableMode::kRpg) {
    return {"ape_trans", "ape_rot", "rpe_trans_10pct", "rpe_trans_20pct", "rpe_trans_30pct", "rpe_trans_40pct",
            "rpe_trans_50pct"};
  }
  return {"ape_trans", "ape_rot", "rpe_trans_10m", "rpe_rot_10m", "ase"};
}

bool IsRpgLayout(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec) && !RunFolders(path).empty();
}

Experiment ReadRpgLayout(const std::string& root, TableMode mode) {
  if (!fs::is_directory(root)) throw InputError(root, 0, 0, "not a folder");
  Experiment e;
  e.mode = mode;
  e.metrics = DefaultMetrics(mode);
  for (const fs::path& folder : RunFolders(root)) {
    const std::string alg = folder.parent_path().filename().string();
    const std::string platform = folder.parent_path().parent_path().filename().string();
    std::string name = folder.filename().string();
    const std::string prefix = platform + "_" + alg + "_";
    const std::string dataset = name.starts_with(prefix) && name.size() > prefix.size() ? name.substr(prefix.size()) : name;
    RunSpec base;
    base.dataset = dataset;
    base.folder = folder.string();
    base.rpg = ReadRpgEvalConfig(folder.string());
    base.align = ChevalAlign(base.rpg.align_type);
    base.align_frames = base.rpg.align_num_frames;
    base.reference = FindReference(folder, platform, dataset);
    if (base.reference.empty()) {
      base.missing = fmt::format("no stamped_groundtruth.txt in {} nor in another algorithm's folder of {}",
                                 folder.string(), dataset);
    }
    const FolderTrials trials = ListTrials(folder);
    base.algorithm = alg;
    AddTrials(&e, trials.traj, base);
    base.algorithm = trials.traj.empty() ? alg : alg + "/ba";  // "/ba" only beside real-time estimates
    AddTrials(&e, trials.ba, base);
  }
  if (e.runs.empty()) {
    throw InputError(root, 0, 0,
                     "no run found: expected <platform>/<alg>/<platform>_<alg>_<dataset>/stamped_traj_estimate*.txt "
                     "(rpg_trajectory_evaluation's layout) or an experiment .yaml file");
  }
  std::stable_sort(e.runs.begin(), e.runs.end(), [](const RunSpec& a, const RunSpec& b) {
    return std::tie(a.algorithm, a.dataset, a.trial) < std::tie(b.algorithm, b.dataset, b.trial);
  });
  return e;
}

namespace {

[[noreturn]] void Bad(const std::string& path, const YAML::Node& node, const std::string& what) {
  throw InputError(path, node.Mark().line + 1, node.Mark().column + 1, what);
}

template <typename T>
T As(const std::string& path, const YAML::Node& node, const std::string& key, const char* expected) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    Bad(path, node, fmt::format("'{}' must be {}", key, expected));
  }
}

}  // namespace

Experiment ReadExperimentConfig(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path, 0, 0, "cannot open the file");
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, e.mark.column + 1, e.msg);
  }
  if (!root.IsMap()) throw InputError(path, 0, 0, "expected a mapping (datasets, algorithms, metrics ...)");
  static const std::vector<std::string> known = {"mode",  "metrics",      "statistic", "max_diff",  "align",
                                                 "align_frames", "rpg_root", "datasets", "algorithms"};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      Bad(path, kv.first, fmt::format("unknown key '{}' (known: {})", key, fmt::join(known, ", ")));
    }
  }
  const fs::path base = fs::path(path).parent_path();
  auto resolve = [&](const std::string& p) { return fs::path(p).is_absolute() ? p : (base / p).lexically_normal().string(); };
  TableMode mode = TableMode::kCheval;
  if (root["mode"]) {
    const std::string m = As<std::string>(path, root["mode"], "mode", "cheval or rpg");
    if (m != "cheval" && m != "rpg") Bad(path, root["mode"], "'mode' must be cheval or rpg, got '" + m + "'");
    mode = m == "rpg" ? TableMode::kRpg : TableMode::kCheval;
  }
  Experiment e;
  if (root["rpg_root"]) {
    e = ReadRpgLayout(resolve(As<std::string>(path, root["rpg_root"], "rpg_root", "a folder")), mode);
  }
  e.mode = mode;
  e.metrics = root["metrics"] ? As<std::vector<std::string>>(path, root["metrics"], "metrics", "a list of names")
                              : DefaultMetrics(mode);
  if (root["statistic"]) {
    e.statistic = As<std::string>(path, root["statistic"], "statistic", "rmse, mean or median");
    if (e.statistic != "rmse" && e.statistic != "mean" && e.statistic != "median") {
      Bad(path, root["statistic"], "'statistic' must be rmse, mean or median");
    }
  }
  if (root["max_diff"]) {
    e.max_diff_s = As<double>(path, root["max_diff"], "max_diff", "a number of seconds");
    if (!(e.max_diff_s >= 0) || !std::isfinite(e.max_diff_s)) Bad(path, root["max_diff"], "'max_diff' must be >= 0");
  }
  std::string align = "se3";
  int frames = -1;
  if (root["align"]) align = As<std::string>(path, root["align"], "align", "an alignment name");
  if (root["align_frames"]) frames = As<int>(path, root["align_frames"], "align_frames", "an integer (-1: all)");
  if (root["align"]) {
    const bool rpg_name = align == "posyaw" || align == "sim3" || align == "se3" || align == "none";
    if (mode == TableMode::kRpg ? !rpg_name : !eval::AlignmentMethodFromString(align)) {
      Bad(path, root["align"], fmt::format("'align' must be {}, got '{}'",
                                           mode == TableMode::kRpg ? "posyaw, sim3, se3 or none"
                                                                   : "none, origin, se3, sim3, scale, posyaw or full",
                                           align));
    }
  }
  if (frames == 0 || frames < -1) Bad(path, root["align_frames"], "'align_frames' must be -1 (all) or >= 1");
  if (root["align"] || root["align_frames"]) {
    for (RunSpec& run : e.runs) {
      run.align = align;
      run.align_frames = frames;
      run.rpg.align_type = align;
      run.rpg.align_num_frames = frames;
    }
  }
  std::map<std::string, std::pair<std::string, std::string>> datasets;  // name -> (reference, label)
  if (root["datasets"]) {
    if (!root["datasets"].IsMap()) Bad(path, root["datasets"], "'datasets' must map names to {reference, label}");
    for (const auto& kv : root["datasets"]) {
      const std::string name = kv.first.as<std::string>();
      const YAML::Node& d = kv.second;
      if (!d.IsMap() || !d["reference"]) Bad(path, kv.first, "dataset '" + name + "' needs a 'reference' file");
      const std::string ref = resolve(As<std::string>(path, d["reference"], "reference", "a file"));
      datasets[name] = {ref, d["label"] ? As<std::string>(path, d["label"], "label", "text") : name};
    }
  }
  if (root["algorithms"]) {
    if (!root["algorithms"].IsSequence()) Bad(path, root["algorithms"], "'algorithms' must be a list");
    for (const YAML::Node& a : root["algorithms"]) {
      if (!a.IsMap() || !a["name"] || !a["estimates"]) Bad(path, a, "an algorithm needs 'name' and 'estimates'");
      const std::string name = As<std::string>(path, a["name"], "name", "text");
      const std::string label = a["label"] ? As<std::string>(path, a["label"], "label", "text") : name;
      if (!a["estimates"].IsMap()) Bad(path, a["estimates"], "'estimates' must map dataset names to lists of files");
      for (const auto& kv : a["estimates"]) {
        const std::string dataset = kv.first.as<std::string>();
        const auto it = datasets.find(dataset);
        if (it == datasets.end()) Bad(path, kv.first, "dataset '" + dataset + "' is not listed under 'datasets'");
        std::vector<std::string> files;
        if (kv.second.IsScalar()) {
          files.push_back(kv.second.as<std::string>());
        } else {
          files = As<std::vector<std::string>>(path, kv.second, dataset, "a file or a list of files (one per trial)");
        }
        for (size_t k = 0; k < files.size(); ++k) {
          RunSpec run;
          run.algorithm = label;
          run.dataset = it->second.second;
          run.trial = static_cast<int>(k);
          run.reference = it->second.first;
          run.estimate = resolve(files[k]);
          run.align = align;
          run.align_frames = frames;
          run.rpg.align_type = align;
          run.rpg.align_num_frames = frames;
          e.runs.push_back(run);
        }
      }
    }
  }
  if (e.runs.empty()) throw InputError(path, 0, 0, "no run: give 'algorithms' with 'estimates', or 'rpg_root'");
  return e;
}

void CheckMetrics(const Experiment& e) {
  static const std::regex cheval_re(R"(ape_trans|ape_rot|ase|kitti_drift_trans|kitti_drift_rot|rpe_(trans|rot)_(\d+(\.\d+)?)m)");
  static const std::regex rpg_re(R"(ape_trans|ape_rot|rpe_(trans|rot)_(\d+)pct)");
  if (e.metrics.empty()) throw UsageError("no metric to tabulate");
  for (const std::string& m : e.metrics) {
    std::smatch match;
    const bool rpg = e.mode == TableMode::kRpg;
    if (!std::regex_match(m, match, rpg ? rpg_re : cheval_re)) {
      throw UsageError(fmt::format(
          "unknown metric '{}' in {} mode (known: {})", m, rpg ? "rpg" : "cheval",
          rpg ? "ape_trans, ape_rot, rpe_trans_<P>pct, rpe_rot_<P>pct with P in 1..100"
              : "ape_trans, ape_rot, rpe_trans_<D>m, rpe_rot_<D>m, ase, kitti_drift_trans, kitti_drift_rot"));
    }
    if (match[2].matched && std::stod(match[2].str()) <= 0) throw UsageError("metric '" + m + "': the distance must be > 0");
    if (rpg && match[2].matched && std::stoi(match[2].str()) > 100) {
      throw UsageError("metric '" + m + "': the percentage must be 1..100");
    }
  }
}

}  // namespace cheval::table

// Reading rpg_trajectory_evaluation's files: `stamped_*.txt` as np.loadtxt reads them and the
// folder's `eval_cfg.yaml` / `start_end_time.yaml` (trajectory.py, Trajectory.__init__).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "cheval/common/error.h"
#include "cheval/table/rpg.h"

namespace cheval::table {

RpgPoses ReadRpgPoses(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, 0, "cannot open the file");
  RpgPoses poses;
  std::vector<Eigen::Matrix<double, 8, 1>> rows;
  std::string line;
  int64_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    for (char& c : line) {
      if (c == ',' || c == '\t' || c == '\r') c = ' ';
    }
    std::istringstream fields(line);
    std::string token;
    Eigen::Matrix<double, 8, 1> row;
    int k = 0;
    while (fields >> token) {
      if (k == 8) break;  // further columns are ignored
      errno = 0;
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(v)) {
        throw InputError(path, number, 0,
                         fmt::format("expected a finite number in column {} (time x y z qx qy qz qw), got '{}'", k + 1,
                                     token));
      }
      row[k++] = v;
    }
    if (k == 0) continue;
    if (k < 8) {
      throw InputError(path, number, 0,
                       fmt::format("expected 8 columns (time x y z qx qy qz qw), got {}", k));
    }
    rows.push_back(row);
  }
  if (in.bad()) throw InputError(path, 0, 0, "read error");
  const auto n = static_cast<Eigen::Index>(rows.size());
  poses.t.resize(rows.size());
  poses.p.resize(3, n);
  poses.q.resize(4, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& r = rows[static_cast<size_t>(i)];
    poses.t[static_cast<size_t>(i)] = r[0];
    poses.p.col(i) = r.segment<3>(1);
    poses.q.col(i) = r.segment<4>(4);
  }
  return poses;
}

namespace {

YAML::Node LoadYaml(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, e.mark.column + 1, e.msg);
  }
}

double YamlDouble(const YAML::Node& node, const std::string& path, const char* key) {
  try {
    return node[key].as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(path, node[key].Mark().line + 1, 0, fmt::format("'{}' must be a number", key));
  }
}

}  // namespace

RpgEvalConfig ReadRpgEvalConfig(const std::string& folder) {
  RpgEvalConfig config;
  namespace fs = std::filesystem;
  const std::string cfg = (fs::path(folder) / "eval_cfg.yaml").string();
  if (fs::exists(cfg)) {
    const YAML::Node node = LoadYaml(cfg);
    if (!node.IsMap()) throw InputError(cfg, 0, 0, "expected a mapping with align_type and align_num_frames");
    if (node["align_type"]) {
      config.align_type = node["align_type"].as<std::string>();
      if (config.align_type != "posyaw" && config.align_type != "sim3" && config.align_type != "se3" &&
          config.align_type != "none") {
        throw InputError(cfg, node["align_type"].Mark().line + 1, 0,
                         fmt::format("align_type must be posyaw, sim3, se3 or none, got '{}'", config.align_type));
      }
    }
    if (node["align_num_frames"]) {
      try {
        config.align_num_frames = node["align_num_frames"].as<int>();
      } catch (const YAML::Exception&) {
        throw InputError(cfg, node["align_num_frames"].Mark().line + 1, 0,
                         "align_num_frames must be an integer (-1 for all frames)");
      }
    }
  }
  const std::string times = (fs::path(folder) / "start_end_time.yaml").string();
  if (fs::exists(times)) {
    const YAML::Node node = LoadYaml(times);
    if (node.IsMap() && node["start_time_sec"]) config.start_time_s = YamlDouble(node, times, "start_time_sec");
    if (node.IsMap() && node["end_time_sec"]) config.end_time_s = YamlDouble(node, times, "end_time_sec");
  }
  return config;
}

}  // namespace cheval::table

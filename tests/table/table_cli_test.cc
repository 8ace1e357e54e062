// `cheval table` end to end: every number of the table equals `cheval ape/rpe/ase` run by hand on
// that run; mean/std over trials; failed trials counted; the per-run cache re-evaluates only new
// runs; rpg's layout with eval_cfg.yaml; bad input and its exit codes.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../cli/cli_runner.h"

namespace cheval::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class TableCliTest : public CliTest {
 protected:
  // Simulated car drives (the project's own simulator): a measured reference without velocity
  // (so the ASE's reference velocity is the shared Chebyshev fit) and `estimates` odometry-like
  // estimates with velocity, per seed.
  void Simulate(const std::string& name, int seed, int estimates) {
    std::string args = fmt::format("sim motion --kind car --duration 40 --seed {} -o {} --estimate-rate 20", seed,
                                   Path(name + "_ref.txt"));
    for (int k = 0; k < estimates; ++k) args += fmt::format(" --estimate {}", Path(fmt::format("{}_est{}.txt", name, k)));
    args += " --estimate-drift";
    for (int k = 0; k < estimates; ++k) args += fmt::format(" {}", 0.002 * (k + 1));
    ASSERT_EQ(Cheval(args).exit_code, 0);
  }

  static json ReadJson(const std::string& path) { return json::parse(Slurp(path)); }

  void WriteFile(const std::string& name, const std::string& text) const { std::ofstream(Path(name)) << text; }
};

// Two algorithms × two datasets × two or three trials, every metric of cheval mode.
constexpr const char* kConfig = R"(metrics: [ape_trans, ape_rot, rpe_trans_10m, rpe_rot_10m, ase, kitti_drift_trans]
align: se3
datasets:
  seqA: {reference: A_ref.txt, label: "Seq A"}
  seqB: {reference: B_ref.txt}
algorithms:
  - name: slow
    label: "Slow drift"
    estimates:
      seqA: [A_est0.txt, A_est2.txt]
      seqB: [B_est0.txt, B_est2.txt]
  - name: fast
    estimates:
      seqA: [A_est1.txt, A_est3.txt]
      seqB: [B_est1.txt, B_est3.txt]
)";

TEST_F(TableCliTest, EveryNumberEqualsTheCommandByHand) {
  Simulate("A", 11, 4);
  Simulate("B", 12, 4);
  WriteFile("exp.yaml", kConfig);
  const RunResult run = Cheval(fmt::format("table {} -o {} --json {} -j 2", Path("exp.yaml"), Path("t.md"), Path("t.json")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json table = ReadJson(Path("t.json"));
  ASSERT_EQ(table["rows"].size(), 2u * 2u * 6u);
  const std::map<std::string, std::string> dataset_files = {{"Seq A", "A"}, {"seqB", "B"}};
  const std::map<std::string, std::vector<int>> estimate_numbers = {{"Slow drift", {0, 2}}, {"fast", {1, 3}}};
  int checked = 0;
  for (const json& row : table["rows"]) {
    for (const char* key : {"algorithm", "dataset", "metric", "trials", "mean", "std", "failed"}) {
      ASSERT_TRUE(row.contains(key)) << key;
    }
    const std::string metric = row["metric"];
    const std::string prefix = dataset_files.at(row["dataset"]);
    std::vector<double> values;
    for (size_t k = 0; k < row["trials"].size(); ++k) {
      ASSERT_FALSE(row["trials"][k].is_null()) << row.dump();
      const double value = row["trials"][k];
      values.push_back(value);
      const std::string ref = Path(prefix + "_ref.txt");
      const std::string est = Path(fmt::format("{}_est{}.txt", prefix, estimate_numbers.at(row["algorithm"])[k]));
      std::string args;
      static const std::regex rpe(R"(rpe_(trans|rot)_(\d+)m)");
      std::smatch m;
      if (metric == "ape_trans" || metric == "ape_rot") {
        args = fmt::format("ape {} {} --align se3 -r {}", ref, est, metric == "ape_trans" ? "trans_part" : "angle_deg");
      } else if (std::regex_match(metric, m, rpe)) {
        args = fmt::format("rpe {} {} --align se3 -r {} --delta {} --delta-unit meters", ref, est,
                           m[1] == "trans" ? "trans_part" : "angle_deg", m[2].str());
      } else if (metric == "ase") {
        args = fmt::format("ase {} {} --align se3", ref, est);
      } else {
        args = fmt::format("rpe {} {} --align se3 --kitti-drift", ref, est);
      }
      const RunResult hand = Cheval(args + " --json " + Path("hand.json"));
      ASSERT_EQ(hand.exit_code, 0) << args << hand.err;
      const json h = ReadJson(Path("hand.json"));
      const double expected = metric == "kitti_drift_trans" ? h["drift"]["translation_percent"].get<double>()
                                                            : h["stats"]["rmse"].get<double>();
      EXPECT_EQ(value, expected) << args;
      ++checked;
    }
    double mean = 0, var = 0;
    for (double v : values) mean += v / static_cast<double>(values.size());
    for (double v : values) var += (v - mean) * (v - mean) / static_cast<double>(values.size());
    EXPECT_NEAR(row["mean"].get<double>(), mean, 1e-12 * std::abs(mean));
    EXPECT_NEAR(row["std"].get<double>(), std::sqrt(var), 1e-12 * std::abs(mean));
    EXPECT_EQ(row["failed"], 0);
  }
  EXPECT_EQ(checked, 2 * 2 * 6 * 2);
  // The Markdown names the labels and marks one best per dataset and metric.
  const std::string md = Slurp(Path("t.md"));
  EXPECT_NE(md.find("| Slow drift | Seq A |"), std::string::npos) << md;
  EXPECT_NE(md.find("**"), std::string::npos);
}

TEST_F(TableCliTest, CacheReevaluatesOnlyTheNewRun) {
  Simulate("A", 21, 3);
  WriteFile("exp.yaml", "metrics: [ape_trans, rpe_trans_10m]\ndatasets:\n  a: {reference: A_ref.txt}\n"
                        "algorithms:\n  - name: x\n    estimates:\n      a: [A_est0.txt, A_est1.txt]\n");
  const std::string args = fmt::format("table {} -o {} --json {}", Path("exp.yaml"), Path("t.md"), Path("t.json"));
  RunResult run = Cheval(args);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("2 evaluated, 0 from the cache"), std::string::npos) << run.err;
  const std::string first = Slurp(Path("t.json"));
  run = Cheval(args);
  EXPECT_NE(run.err.find("0 evaluated, 2 from the cache"), std::string::npos) << run.err;
  EXPECT_EQ(Slurp(Path("t.json")), first);  // the cached numbers are the same numbers
  WriteFile("exp.yaml", "metrics: [ape_trans, rpe_trans_10m]\ndatasets:\n  a: {reference: A_ref.txt}\n"
                        "algorithms:\n  - name: x\n    estimates:\n      a: [A_est0.txt, A_est1.txt, A_est2.txt]\n");
  run = Cheval(args + " -j 2");
  EXPECT_NE(run.err.find("1 evaluated, 2 from the cache"), std::string::npos) << run.err;
  // A changed estimate file is a new run.
  std::ofstream(Path("A_est1.txt"), std::ios::app) << "\n";
  run = Cheval(args);
  EXPECT_NE(run.err.find("1 evaluated, 2 from the cache"), std::string::npos) << run.err;
  run = Cheval(args + " --no-cache");
  EXPECT_NE(run.err.find("3 evaluated, 0 from the cache"), std::string::npos) << run.err;
}

// rpg's layout: eval_cfg.yaml's alignment, numbered trials with one missing, a folder without
// ground truth taking its dataset's from another algorithm's folder.
TEST_F(TableCliTest, RpgLayoutCountsMissingTrials) {
  Simulate("A", 31, 3);
  const fs::path a = dir_ / "exp/laptop/algA/laptop_algA_MH_01", b = dir_ / "exp/laptop/algB/laptop_algB_MH_01";
  fs::create_directories(a);
  fs::create_directories(b);
  // rpg's files hold 8 columns: the reference and estimates without velocity.
  ASSERT_EQ(Cheval(fmt::format("convert {} -o {} --to tum", Path("A_ref.txt"), (a / "stamped_groundtruth.txt").string())).exit_code, 0);
  for (int k : {0, 2}) {
    ASSERT_EQ(Cheval(fmt::format("convert {} -o {} --to tum", Path(fmt::format("A_est{}.txt", k)),
                                 (a / fmt::format("stamped_traj_estimate{}.txt", k)).string()))
                  .exit_code,
              0);
  }
  ASSERT_EQ(Cheval(fmt::format("convert {} -o {} --to tum", Path("A_est1.txt"), (b / "stamped_traj_estimate.txt").string())).exit_code, 0);
  // Bundle-adjusted estimates beside real-time ones are the algorithm "<alg>/ba".
  fs::copy_file(b / "stamped_traj_estimate.txt", b / "stamped_ba_estimate0.txt");
  std::ofstream(a / "eval_cfg.yaml") << "align_type: posyaw\nalign_num_frames: -1\n";
  std::ofstream(b / "eval_cfg.yaml") << "align_type: sim3\nalign_num_frames: -1\n";
  const RunResult run = Cheval(fmt::format("table {} -o {} -j 2", (dir_ / "exp").string(), Path("t.json")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json table = ReadJson(Path("t.json"));
  bool seen_a = false, seen_b = false, seen_ba = false;
  for (const json& row : table["rows"]) {
    EXPECT_EQ(row["dataset"], "MH_01");
    if (row["algorithm"] == "algA") {
      seen_a = true;
      ASSERT_EQ(row["trials"].size(), 3u);
      EXPECT_TRUE(row["trials"][1].is_null());
      EXPECT_EQ(row["failed"], 1);
      if (row["metric"] == "ape_trans") {
        const RunResult hand = Cheval(fmt::format("ape {} {} --align posyaw --json {}", (a / "stamped_groundtruth.txt").string(),
                                                  (a / "stamped_traj_estimate2.txt").string(), Path("h.json")));
        ASSERT_EQ(hand.exit_code, 0) << hand.err;
        EXPECT_EQ(row["trials"][2].get<double>(), ReadJson(Path("h.json"))["stats"]["rmse"].get<double>());
      }
    } else if (row["algorithm"] == "algB/ba") {
      seen_ba = true;
      EXPECT_EQ(row["failed"], 0);
    } else {
      seen_b = true;
      EXPECT_EQ(row["algorithm"], "algB");
      EXPECT_EQ(row["failed"], 0);
      if (row["metric"] == "ape_trans") {
        const RunResult hand = Cheval(fmt::format("ape {} {} --align sim3 --json {}", (a / "stamped_groundtruth.txt").string(),
                                                  (b / "stamped_traj_estimate.txt").string(), Path("h.json")));
        EXPECT_EQ(row["trials"][0].get<double>(), ReadJson(Path("h.json"))["stats"]["rmse"].get<double>());
      }
    }
  }
  EXPECT_TRUE(seen_a && seen_b && seen_ba);
  // rpg mode on the same folder gives its metric names and finite numbers for the present trials.
  const RunResult rpg = Cheval(fmt::format("table {} --rpg -o {} --latex {} --html {}", (dir_ / "exp").string(),
                                           Path("r.json"), Path("r.tex"), Path("r.html")));
  ASSERT_EQ(rpg.exit_code, 0) << rpg.err;
  const json r = ReadJson(Path("r.json"));
  EXPECT_EQ(r["mode"], "rpg");
  EXPECT_EQ(r["rows"][0]["metric"], "ape_trans");
  EXPECT_TRUE(std::isfinite(r["rows"][0]["trials"][0].get<double>()));
  const std::string tex = Slurp(Path("r.tex"));
  for (const char* part : {"\\toprule", "\\midrule", "\\bottomrule", "\\begin{tabular}", "\\end{tabular}"}) {
    EXPECT_NE(tex.find(part), std::string::npos) << part;
  }
  EXPECT_NE(Slurp(Path("r.html")).find("</html>"), std::string::npos);
}

TEST_F(TableCliTest, BadInputExitCodes) {
  EXPECT_EQ(Cheval(fmt::format("table {} -o {}", Path("nothing"), Path("t.md"))).exit_code, 2);
  WriteFile("bad.yaml", "metrics: [ape_trans]\ndatasets:\n  a: {label: x}\n");
  RunResult run = Cheval(fmt::format("table {} -o {}", Path("bad.yaml"), Path("t.md")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("bad.yaml:3"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("reference"), std::string::npos) << run.err;
  Simulate("A", 41, 1);
  WriteFile("al.yaml", "align: yawonly\ndatasets:\n  a: {reference: A_ref.txt}\n"
                       "algorithms:\n  - name: x\n    estimates: {a: A_est0.txt}\n");
  run = Cheval(fmt::format("table {} -o {}", Path("al.yaml"), Path("t.md")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("al.yaml:1"), std::string::npos) << run.err;
  WriteFile("m.yaml", "metrics: [ape_speed]\ndatasets:\n  a: {reference: A_ref.txt}\n"
                      "algorithms:\n  - name: x\n    estimates: {a: A_est0.txt}\n");
  run = Cheval(fmt::format("table {} -o {}", Path("m.yaml"), Path("t.md")));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("ape_speed"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(Path("t.md")));
  // Every run failing (an estimate that does not exist) is exit 3 and writes nothing.
  WriteFile("f.yaml", "datasets:\n  a: {reference: A_ref.txt}\nalgorithms:\n  - name: x\n    estimates: {a: none.txt}\n");
  run = Cheval(fmt::format("table {} -o {}", Path("f.yaml"), Path("t.md")));
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("none.txt"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(Path("t.md")));
}

}  // namespace
}  // namespace cheval::testing

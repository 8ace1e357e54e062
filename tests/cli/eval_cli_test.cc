// `cheval ape | rpe | ase` end to end: hand-checkable values through the executable, the JSON keys of
// docs/evaluation.md ("Output"), the per-pair CSV, the comparison table for several estimates, and every bad input
// of issue 4 with its documented exit code and no output file left behind.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <Eigen/Core>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/test_data.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;

class EvalCliTest : public ::testing::Test {
 protected:
  struct Output {
    int code = -1;
    std::string stdout_text, stderr_text;
  };

  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    folder_ = fs::temp_directory_path() / fmt::format("cheval_eval_cli_{}_{}", test, ::getpid());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  std::string File(const std::string& name) const { return (folder_ / name).string(); }

  static std::string Read(const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  // `cheval ARGS`, its exit code and both streams.
  Output Run(const std::string& args) const {
    const std::string out = File(".out"), err = File(".err");
    const int status = std::system(fmt::format("{} {} >{} 2>{}", CHEVAL_EXE, args, out, err).c_str());
    Output o{WIFEXITED(status) ? WEXITSTATUS(status) : -1, Read(out), Read(err)};
    fs::remove(out);
    fs::remove(err);
    return o;
  }

  // A helix at 100 Hz for `seconds`, yaw along the path, world velocity; every state shifted by
  // `shift` (m) and stamps by `stamp_offset_s`. TUM (8 columns) or TUM + velocity (11).
  std::string Helix(const std::string& name, double seconds, const Eigen::Vector3d& shift = Eigen::Vector3d::Zero(),
                    bool velocity = true, double stamp_offset_s = 0.0) const {
    std::ofstream f(File(name));
    for (int i = 0; i <= static_cast<int>(seconds * 100); ++i) {
      const double t = i * 0.01;
      const Eigen::Vector3d p = Eigen::Vector3d(std::cos(t), std::sin(t), 0.1 * t) + shift;
      f << fmt::format("{:.2f} {} {} {} 0 0 {} {}", 1000.0 + t + stamp_offset_s, p.x(), p.y(), p.z(),
                       std::sin(t / 2), std::cos(t / 2));
      if (velocity) f << fmt::format(" {} {} 0.1", -std::sin(t), std::cos(t));
      f << "\n";
    }
    return File(name);
  }

  fs::path folder_;
};

// An estimate shifted by 0.3 m along x: APE 0.3 everywhere without alignment, ~0 after SE(3); the
// JSON has exactly the keys of docs/evaluation.md ("Output"); the CSV has one row per pair.
TEST_F(EvalCliTest, ApeHandCheckedJsonAndCsv) {
  const std::string ref = Helix("ref.txt", 10), est = Helix("est.txt", 10, {0.3, 0, 0});
  const Output run = Run(fmt::format("ape {} {} --json {} --errors {}", ref, est, File("r.json"), File("e.csv")));
  ASSERT_EQ(run.code, 0) << run.stderr_text;
  EXPECT_NE(run.stdout_text.find("APE w.r.t. translation part (m)\n(not aligned)"), std::string::npos);
  EXPECT_NE(run.stdout_text.find("      rmse\t0.300000"), std::string::npos) << run.stdout_text;
  const nlohmann::json j = nlohmann::json::parse(Read(File("r.json")));
  std::vector<std::string> keys;
  for (const auto& item : j.items()) keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"alignment", "association", "command", "estimate", "metric", "reference",
                                            "stats"}));  // nlohmann sorts keys when parsing
  EXPECT_EQ(j["command"], "ape");
  EXPECT_EQ(j["reference"]["poses"], 1001);
  EXPECT_EQ(j["association"]["pairs"], 1001);
  EXPECT_DOUBLE_EQ(j["association"]["max_diff"].get<double>(), 0.01);
  EXPECT_EQ(j["alignment"]["method"], "none");
  EXPECT_EQ(j["alignment"]["rotation"][1][1], 1.0);
  EXPECT_EQ(j["metric"]["relation"], "trans_part");
  EXPECT_EQ(j["metric"]["unit"], "m");
  for (const char* key : {"rmse", "mean", "median", "min", "max"}) {
    EXPECT_NEAR(j["stats"][key].get<double>(), 0.3, 1e-12) << key;  // |(x + 0.3) - x| rounds by ~1e-16
  }
  EXPECT_NEAR(j["stats"]["std"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(j["stats"]["sse"].get<double>(), 1001 * 0.09, 1e-12 * 1001 * 0.09);
  EXPECT_EQ(j["stats"]["n"], 1001);
  const std::string csv = Read(File("e.csv"));
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "stamp,error");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1002);
  EXPECT_EQ(csv.substr(csv.find('\n') + 1, 15), "1000.000000000,");

  const Output aligned = Run(fmt::format("ape {} {} --align se3 --json {}", ref, est, File("a.json")));
  ASSERT_EQ(aligned.code, 0) << aligned.stderr_text;
  const nlohmann::json a = nlohmann::json::parse(Read(File("a.json")));
  EXPECT_LT(a["stats"]["rmse"].get<double>(), 1e-12);
  EXPECT_NEAR(a["alignment"]["translation"][0].get<double>(), -0.3, 1e-12);
  EXPECT_EQ(a["alignment"]["scale"], 1.0);
}

// Several estimates: an array of results and one comparison table (RMSE, STD, median).
TEST_F(EvalCliTest, SeveralEstimatesGiveOneTable) {
  const std::string ref = Helix("ref.txt", 5);
  const std::string a = Helix("a.txt", 5, {0.1, 0, 0}), b = Helix("b.txt", 5, {0, 0.2, 0});
  const Output run = Run(fmt::format("ape {} {} {} --json {} --errors {}", ref, a, b, File("r.json"), File("e.csv")));
  ASSERT_EQ(run.code, 0) << run.stderr_text;
  const nlohmann::json j = nlohmann::json::parse(Read(File("r.json")));
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 2u);
  EXPECT_NEAR(j[1]["stats"]["rmse"].get<double>(), 0.2, 1e-12);
  EXPECT_NE(run.stdout_text.find("2 estimates"), std::string::npos);
  // Named by the file name (the default --label), in a column of at least 8 characters.
  EXPECT_NE(run.stdout_text.find("\na.txt         0.100000      0.000000      0.100000       501"), std::string::npos)
      << run.stdout_text;
  EXPECT_EQ(Read(File("e.csv")).substr(0, 24), "estimate,stamp,error\n" + a.substr(0, 3));
}

// --t-offset: est + offset = ref. Stamps 5 s late are matched back with --t-offset -5.
TEST_F(EvalCliTest, OffsetRestoresTheAssociation) {
  const std::string ref = Helix("ref.txt", 5), late = Helix("late.txt", 5, {0.1, 0, 0}, true, 5.0);
  const Output none = Run(fmt::format("ape {} {}", ref, late));
  EXPECT_EQ(none.code, 0) << none.stderr_text;  // the files share one stamp, 1005.00 s
  const Output shifted = Run(fmt::format("ape {} {} --t-offset -5 --json {}", ref, late, File("r.json")));
  ASSERT_EQ(shifted.code, 0) << shifted.stderr_text;
  EXPECT_EQ(nlohmann::json::parse(Read(File("r.json")))["association"]["pairs"], 501);
  EXPECT_NEAR(nlohmann::json::parse(Read(File("r.json")))["stats"]["max"].get<double>(), 0.1, 1e-12);
}

TEST_F(EvalCliTest, RpeFramesAndDeltaUnits) {
  const std::string ref = Helix("ref.txt", 10), est = Helix("est.txt", 10, {0.3, 0, 0});
  const Output run = Run(fmt::format("rpe {} {} --delta 10 --delta-unit frames --json {}", ref, est, File("r.json")));
  ASSERT_EQ(run.code, 0) << run.stderr_text;
  EXPECT_NE(run.stdout_text.find("for delta = 10 (frames) using consecutive pairs"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(Read(File("r.json")));
  EXPECT_EQ(j["stats"]["n"], 100);                         // floor(1000 / 10) pairs
  EXPECT_LT(j["stats"]["max"].get<double>(), 1e-12);       // a shift leaves every motion unchanged
  EXPECT_EQ(j["metric"]["delta_unit"], "frames");
  const Output letters = Run(fmt::format("rpe {} {} --delta 1 -u m --all-pairs -r angle_deg", ref, est));
  EXPECT_EQ(letters.code, 0) << letters.stderr_text;
  EXPECT_NE(letters.stdout_text.find("RPE w.r.t. rotation angle in degrees (deg)\nfor delta = 1.0 (m) using all pairs"),
            std::string::npos)
      << letters.stdout_text;
}

// ASE with the reference's own velocity, and C-ASE from its positions (a smooth helix: the two
// agree to ~1e-10 m/s).
TEST_F(EvalCliTest, AseGivenAndChebyshevVelocity) {
  const std::string ref = Helix("ref.txt", 10), est = Helix("est.txt", 10, {0.3, 0, 0});
  const Output given = Run(fmt::format("ase {} {} --json {}", ref, est, File("g.json")));
  ASSERT_EQ(given.code, 0) << given.stderr_text;
  const nlohmann::json g = nlohmann::json::parse(Read(File("g.json")));
  EXPECT_EQ(g["velocity_source"], "given");
  EXPECT_EQ(g["metric"]["name"], "ASE");
  EXPECT_NEAR(g["stats"]["rmse"].get<double>(), 0.3, 1e-12);  // only the position part: R and v agree
  for (const char* part : {"rotation", "position", "velocity"}) EXPECT_TRUE(g["parts"].contains(part)) << part;
  const std::string positions = Helix("positions.txt", 10, Eigen::Vector3d::Zero(), false);
  const Output cheb = Run(fmt::format("ase {} {} --json {}", positions, est, File("c.json")));
  ASSERT_EQ(cheb.code, 0) << cheb.stderr_text;
  const nlohmann::json c = nlohmann::json::parse(Read(File("c.json")));
  EXPECT_EQ(c["velocity_source"], "chebyshev");
  // The C-ASE velocity is the derivative of the Chebyshev fit of exact (shortest round-trip) helix
  // positions: only the fit's truncation and rounding remain, measured 2.2e-10 m/s; ~10x, since the
  // degree the fit selects decides the figure.
  EXPECT_LT(c["parts"]["velocity"]["rmse"].get<double>(), 2e-9);
  const Output full = Run(fmt::format("ase {} {} --align full --errors {}", ref, est, File("e.csv")));
  ASSERT_EQ(full.code, 0) << full.stderr_text;
  const std::string csv = Read(File("e.csv"));
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "stamp,error,rotation,position,velocity");
}

// The bad inputs of issue 4: one clear line, the documented exit code, and no output file.
TEST_F(EvalCliTest, BadInputExitCodesAndNoPartialOutput) {
  const std::string ref = Helix("ref.txt", 2), est = Helix("est.txt", 2);
  const std::string outputs = fmt::format(" --json {} --errors {}", File("r.json"), File("e.csv"));
  // No pair within --t-max-diff: exit 3, both stamp ranges and the hint.
  const std::string far = Helix("far.txt", 2, Eigen::Vector3d::Zero(), true, 100.0);
  const Output none = Run(fmt::format("ape {} {}", ref, far) + outputs);
  EXPECT_EQ(none.code, 3);
  EXPECT_NE(none.stderr_text.find("reference stamps span 1000.000000000 .. 1002.000000000 s, estimate stamps span "
                                  "1100.000000000 .. 1102.000000000 s"),
            std::string::npos)
      << none.stderr_text;
  EXPECT_NE(none.stderr_text.find("--t-offset"), std::string::npos);
  // KITTI files of different lengths: exit 3.
  std::ofstream(File("a.kitti")) << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n";
  std::ofstream(File("b.kitti")) << "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const Output kitti = Run(fmt::format("ape {} {}", File("a.kitti"), File("b.kitti")) + outputs);
  EXPECT_EQ(kitti.code, 3);
  EXPECT_NE(kitti.stderr_text.find("the reference has 2 poses and the estimate 1"), std::string::npos);
  // Fewer than 3 pairs for an alignment.
  const Output few = Run(fmt::format("ape {} {} --align se3 --n-align 2", ref, est) + outputs);
  EXPECT_EQ(few.code, 3);
  EXPECT_EQ(few.stderr_text, "cheval: error: SE(3) Umeyama alignment needs at least 3 associated pairs, got 2 (check "
                             "--t-max-diff, --t-offset or --n-align)\n");
  // ASE with no velocity anywhere.
  const std::string a = Helix("pa.txt", 2, Eigen::Vector3d::Zero(), false), b = Helix("pb.txt", 2, {0.1, 0, 0}, false);
  const Output novel = Run(fmt::format("ase {} {}", a, b) + outputs);
  EXPECT_EQ(novel.code, 3);
  EXPECT_NE(novel.stderr_text.find("ASE needs the estimate's velocity and it has none"), std::string::npos);
  EXPECT_EQ(Run(fmt::format("ase {} {} --pose-only", a, b)).code, 0);
  // Unknown flags and bad values: exit 1.
  EXPECT_EQ(Run(fmt::format("ape {} {} --no-such-flag", ref, est) + outputs).code, 1);
  EXPECT_EQ(Run(fmt::format("ape {} {} --align magic", ref, est) + outputs).code, 1);
  EXPECT_EQ(Run(fmt::format("rpe {} {} --delta-unit miles", ref, est) + outputs).code, 1);
  EXPECT_EQ(Run(fmt::format("rpe {} {} --delta 0", ref, est) + outputs).code, 1);
  EXPECT_EQ(Run(fmt::format("ape {}", ref)).code, 1);  // no estimate
  // A missing file: exit 2.
  EXPECT_EQ(Run(fmt::format("ape {} {}", ref, File("nope.txt")) + outputs).code, 2);
  EXPECT_FALSE(fs::exists(File("r.json")));
  EXPECT_FALSE(fs::exists(File("e.csv")));
  // An unwritable output: exit 4, and no temporary left behind.
  const Output unwritable = Run(fmt::format("ape {} {} --json {}", ref, est, File("no/dir/r.json")));
  EXPECT_EQ(unwritable.code, 4);
  size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(folder_)) ++entries;
  EXPECT_EQ(entries, 7u);  // ref, est, far, a.kitti, b.kitti, pa, pb
}

// A bad option is reported with the flag the user typed (the library names the options field;
// tools/cheval/option_names.cc spells it), exit 1, before any file is read or written.
TEST_F(EvalCliTest, OptionErrorsNameTheFlag) {
  const std::string ref = Helix("r.txt", 2), est = Helix("e.txt", 2, {0.1, 0, 0});
  const std::string json = " --json " + File("r.json");
  const std::pair<std::string, std::string> cases[] = {
      {"ape {} {} --n-align 5", "--n-align needs --align (se3, sim3, scale, posyaw or full)"},
      {"ape {} {} --t-max-diff -1", "--t-max-diff must be >= 0, got -1.000000000 s"},
      {"rpe {} {} --delta 1.5", "--delta must be an integer for --delta-unit frames, got 1.5"},
      {"ase {} {} --pose-only --velocity-frame body", "--pose-only ignores velocity: drop --velocity-frame"},
      {"ase {} {} --association continuous --gt-velocity given",
       "--association continuous takes the reference velocity from its Chebyshev curve: use --gt-velocity auto or "
       "chebyshev"},
      {"ape {} {}.missing --n-align -2 --align se3",
       "--n-align must be at least 1 (leave it out to align on all pairs), got -2"},
  };
  for (const auto& [args, message] : cases) {
    const Output run = Run(fmt::format(fmt::runtime(args), ref, est) + json);
    EXPECT_EQ(run.code, 1) << args;
    EXPECT_EQ(run.stderr_text, "cheval: error: " + message + "\n") << args;
    EXPECT_FALSE(fs::exists(File("r.json")));
  }
  const Output degree = Run(fmt::format("velocity {} --degree foo", ref));
  EXPECT_EQ(degree.code, 1);
  EXPECT_EQ(degree.stderr_text,
            "cheval: error: --degree must be auto, cv, chop or a non-negative integer, got 'foo'\n");
}

// The shared evo files: V1_02 gives evo's 798 pairs (docs/evaluation.md, "Association"), KITTI 00 the drift over every
// segment length (evo's own numbers are checked by evo_parity_test.py).
TEST_F(EvalCliTest, SharedEvoFiles) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string evo = cheval::testing::SharedDataDir() + "/evo/";
  const Output v102 = Run(fmt::format("ape {}V102_groundtruth.csv {}V102.txt --align se3 --json {}", evo, evo,
                                      File("v.json")));
  ASSERT_EQ(v102.code, 0) << v102.stderr_text;
  EXPECT_EQ(nlohmann::json::parse(Read(File("v.json")))["association"]["pairs"], 798);  // docs/evaluation.md, "Association"
  const Output drift = Run(fmt::format("rpe {}KITTI_00_gt.txt {}KITTI_00_ORB.txt --delta 100 -u m --kitti-drift --json {}",
                                       evo, evo, File("k.json")));
  ASSERT_EQ(drift.code, 0) << drift.stderr_text;
  const nlohmann::json k = nlohmann::json::parse(Read(File("k.json")));
  EXPECT_EQ(k["drift"]["lengths"].size(), 8u);
  EXPECT_EQ(k["drift"]["segments"], 3283);  // docs/evaluation.md; the figures: kitti_drift_cli_test.cc
  EXPECT_NE(drift.stdout_text.find("KITTI drift over 100..800 m"), std::string::npos);
}

}  // namespace
}  // namespace cheval

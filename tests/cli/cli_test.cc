// The `cheval` executable end to end: exit codes, the one-line error on stderr, JSON keys, and no
// output file left behind when a command fails.
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/test_data.h"
#include "cli_runner.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;

using cheval::testing::CliTest;
using cheval::testing::RunResult;
using cheval::testing::Slurp;

TEST_F(CliTest, SimInfoConvertPipeline) {
  RunResult sim = Cheval("sim motion --kind drone --seed 3 --noise 0.001 --duration 10 --rate 100 -o " + Path("m.txt") +
                   " --truth " + Path("truth.txt"));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;

  RunResult info = Cheval("info " + Path("truth.txt") + " --json " + Path("info.json"));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("(tumv)"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("info.json")));
  for (const char* key : {"poses", "duration_s", "rate_hz", "path_length_m", "has_velocity", "has_orientation",
                          "duplicate_stamps", "non_increasing_stamps"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["poses"], 1001);
  EXPECT_DOUBLE_EQ(j["duration_s"].get<double>(), 10.0);
  EXPECT_NEAR(j["rate_hz"].get<double>(), 100.0, 1e-9);
  EXPECT_EQ(j["has_velocity"], true);
  EXPECT_EQ(j["duplicate_stamps"], 0);

  RunResult convert = Cheval("convert " + Path("truth.txt") + " -o " + Path("truth.csv"));
  ASSERT_EQ(convert.exit_code, 0) << convert.err;
  EXPECT_EQ(Slurp(Path("truth.csv")).rfind("#timestamp [ns]", 0), 0u);  // .csv -> EuRoC by default
  RunResult back = Cheval("convert " + Path("truth.csv") + " --to tumv -o " + Path("back.txt"));
  ASSERT_EQ(back.exit_code, 0) << back.err;
  // TUM -> EuRoC -> TUM is lossless, except the body angular velocity (wx wy wz, the truth's last 3
  // columns) that EuRoC has no columns for.
  std::istringstream truth_lines(Slurp(Path("truth.txt")));
  std::string without_angular;
  for (std::string line; std::getline(truth_lines, line);) {
    for (int k = 0; k < 3; ++k) line.erase(line.rfind(' '));
    without_angular += line + "\n";
  }
  EXPECT_EQ(Slurp(Path("back.txt")), without_angular);

  RunResult kitti = Cheval("convert " + Path("m.txt") + " --to kitti -o " + Path("m.kitti") + " --times-output " +
                     Path("times.txt"));
  ASSERT_EQ(kitti.exit_code, 0) << kitti.err;
  RunResult kitti_info = Cheval("info " + Path("m.kitti") + " --kitti-times " + Path("times.txt") + " --json " +
                          Path("k.json"));
  ASSERT_EQ(kitti_info.exit_code, 0) << kitti_info.err;
  EXPECT_EQ(nlohmann::json::parse(Slurp(Path("k.json")))["poses"], 1001);
}

TEST_F(CliTest, BadInputIsOneLineAndExitCode2) {
  const std::string bad = cheval::testing::FixturePath("bad/not_a_number.txt");
  RunResult run = Cheval("info " + bad);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_EQ(run.err, bad + ":2:7: error: expected a number for field 3 (y), got 'abc'\n");
  RunResult missing = Cheval("info " + Path("nope.txt"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err, Path("nope.txt") + ":0:0: error: cannot open file: No such file or directory\n");
}

TEST_F(CliTest, FailedConvertLeavesNoFile) {
  RunResult run = Cheval("convert " + cheval::testing::FixturePath("bad/truncated_last_line.txt") + " -o " + Path("out.txt"));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_FALSE(fs::exists(Path("out.txt")));
  // Asking for velocity the input does not have: exit 3, nothing written.
  std::ofstream(Path("pose.txt")) << "1 0 0 0 0 0 0 1\n";
  RunResult no_velocity = Cheval("convert " + Path("pose.txt") + " --to tumv -o " + Path("v.txt"));
  EXPECT_EQ(no_velocity.exit_code, 3);
  EXPECT_EQ(no_velocity.err, "cheval: error: cannot write tumv: the trajectory has no velocity (use `cheval velocity` "
                             "to add it)\n");
  EXPECT_FALSE(fs::exists(Path("v.txt")));
  // An unwritable destination: exit 4 and no temporary file left in the folder.
  RunResult unwritable = Cheval("convert " + Path("pose.txt") + " -o " + Path("no/such/dir/out.txt"));
  EXPECT_EQ(unwritable.exit_code, 4);
  EXPECT_NE(unwritable.err.find("no/such/dir/out.txt: error: cannot write"), std::string::npos);
  // A failed run does not clobber an existing output either.
  std::ofstream(Path("keep.txt")) << "precious\n";
  RunResult clobber = Cheval("convert " + cheval::testing::FixturePath("bad/nan.txt") + " -o " + Path("keep.txt"));
  EXPECT_EQ(clobber.exit_code, 2);
  EXPECT_EQ(Slurp(Path("keep.txt")), "precious\n");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++entries;
  EXPECT_EQ(entries, 4u);  // stdout, stderr, pose.txt, keep.txt
}

TEST_F(CliTest, UsageErrorsExitWith1) {
  EXPECT_EQ(Cheval("info").exit_code, 1);
  EXPECT_EQ(Cheval("info x.txt --no-such-flag").exit_code, 1);
  EXPECT_EQ(Cheval("info x.txt --format bogus").exit_code, 1);
  EXPECT_EQ(Cheval("frobnicate").exit_code, 1);
  RunResult columns = Cheval("info " + cheval::testing::FixturePath("bad/nan.txt") + " --columns t,px,py");
  EXPECT_EQ(columns.exit_code, 1);
  EXPECT_EQ(columns.err, "cheval: error: --columns: expected all three position columns px, py, pz\n");
  RunResult csv = Cheval("info " + cheval::testing::FixturePath("bad/nan.txt") + " --format csv");
  EXPECT_EQ(csv.exit_code, 1);
  EXPECT_EQ(Cheval("sim motion --duration -1 -o " + Path("x.txt")).exit_code, 1);
  EXPECT_FALSE(fs::exists(Path("x.txt")));
  EXPECT_EQ(Cheval("--help").exit_code, 0);
}

// `sim motion --estimate`: simulated estimator outputs that the evaluation commands take as they are,
// worse with more drift; a bad drift list writes no file at all.
TEST_F(CliTest, SimulatedEstimatesAreEvaluated) {
  RunResult sim = Cheval("sim motion --kind drone --seed 4 --duration 30 -o " + Path("m.txt") + " --truth " +
                         Path("t.txt") + " --estimate " + Path("a.txt") + " --estimate " + Path("b.txt") +
                         " --estimate-drift 0.001 0.01 --estimate-rate 10");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_NE(sim.err.find("wrote 2 simulated estimates at 10 Hz"), std::string::npos) << sim.err;
  RunResult ase = Cheval("ase " + Path("t.txt") + " " + Path("a.txt") + " " + Path("b.txt") + " --align se3 --json " +
                         Path("ase.json"));
  ASSERT_EQ(ase.exit_code, 0) << ase.err;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("ase.json")));
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[0]["stats"]["n"], 301);  // 30 s at 10 Hz, every one within 0.01 s of a 200 Hz truth pose
  EXPECT_LT(j[0]["stats"]["rmse"].get<double>(), j[1]["stats"]["rmse"].get<double>());
  EXPECT_GT(j[0]["parts"]["velocity"]["rmse"].get<double>(), 0.0);

  RunResult bad = Cheval("sim motion --duration 5 -o " + Path("x.txt") + " --estimate " + Path("e1.txt") +
                         " --estimate " + Path("e2.txt") + " --estimate-drift 0.1 0.2 0.3");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_EQ(bad.err, "cheval: error: --estimate-drift: give one value or one per --estimate (2), got 3\n");
  EXPECT_FALSE(fs::exists(Path("x.txt")));
  EXPECT_FALSE(fs::exists(Path("e1.txt")));
}

// Velocity RMSE (m/s) of a TUM + velocity file against the truth file, pose by pose.
double VelocityRmse(const std::string& estimate, const std::string& truth) {
  std::ifstream a(estimate), b(truth);
  std::string la, lb;
  double sum = 0;
  int n = 0;
  while (std::getline(a, la) && std::getline(b, lb)) {
    std::istringstream sa(la), sb(lb);
    double va[11], vb[11];
    for (int k = 0; k < 11; ++k) sa >> va[k], sb >> vb[k];
    for (int k = 8; k < 11; ++k) sum += (va[k] - vb[k]) * (va[k] - vb[k]);
    ++n;
  }
  return n > 0 ? std::sqrt(sum / n) : 1e9;
}

TEST_F(CliTest, VelocityFromNoisyPositions) {
  ASSERT_EQ(Cheval("sim motion --kind drone --duration 20 --noise 0.0005 -o " + Path("m.txt") + " --truth " +
                   Path("t.txt"))
                .exit_code,
            0);
  RunResult run = Cheval("velocity " + Path("m.txt") + " -o " + Path("v.txt") + " --json " + Path("v.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  RunResult central = Cheval("velocity " + Path("m.txt") + " --method central -o " + Path("c.txt"));
  ASSERT_EQ(central.exit_code, 0) << central.err;
  const double cheb = VelocityRmse(Path("v.txt"), Path("t.txt")), diff = VelocityRmse(Path("c.txt"), Path("t.txt"));
  // Measured 0.23 mm/s against 123 mm/s for central differences (seeded 0.5 mm noise; the Chebyshev
  // figure moves with the degrees the fit selects): ~2x the measured value, and 100x better.
  EXPECT_LT(cheb, 0.0005) << cheb << " m/s";
  EXPECT_LT(cheb, 0.01 * diff) << cheb << " vs central " << diff;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("v.json")));
  for (const char* key : {"method", "windows", "degrees", "noise_sigma_m", "noise_sigma_max_m", "noisier_samples",
                          "stamp_noise_s", "position_resolution_m", "residual_rmse_m", "compression_ratio",
                          "seconds"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_NEAR(j["noise_sigma_m"][0].get<double>(), 0.0005, 0.0001);
  EXPECT_EQ(j["stamp_noise_s"].get<double>(), 0.0);  // the simulator's stamps are the instants sampled
  for (int c = 0; c < 3; ++c) EXPECT_GE(j["noise_sigma_max_m"][c].get<double>(), j["noise_sigma_m"][c].get<double>());
  EXPECT_GT(j["compression_ratio"].get<double>(), 10.0);
  // --at: evaluate at other stamps (here every 10th measured stamp, from a stamps file).
  std::ofstream at(Path("at.txt"));
  std::ifstream measured(Path("m.txt"));
  std::string line;
  for (int i = 0; std::getline(measured, line); ++i) {
    if (i % 10 == 5) at << line.substr(0, line.find(' ')) << "\n";
  }
  at.close();
  RunResult at_run = Cheval("velocity " + Path("m.txt") + " --at " + Path("at.txt") + " -o " + Path("va.txt"));
  ASSERT_EQ(at_run.exit_code, 0) << at_run.err;
  const std::string evaluated = Slurp(Path("va.txt")), asked = Slurp(Path("at.txt"));
  EXPECT_EQ(std::count(evaluated.begin(), evaluated.end(), '\n'), std::count(asked.begin(), asked.end(), '\n'));
  EXPECT_EQ(evaluated.substr(0, 20), asked.substr(0, 20));  // the same stamps, in order
}

// Columns [first, first + 3) of each line of two files: RMS of their difference.
double ColumnRmse(const std::string& estimate, const std::string& truth, int first) {
  std::ifstream a(estimate), b(truth);
  std::string la, lb;
  double sum = 0;
  int n = 0;
  while (std::getline(a, la) && std::getline(b, lb)) {
    std::istringstream sa(la), sb(lb);
    std::vector<double> va(first + 3), vb(first + 3);
    for (int k = 0; k < first + 3; ++k) sa >> va[k], sb >> vb[k];
    if (!sa || !sb) return 1e9;  // a line with too few columns
    for (int k = first; k < first + 3; ++k) sum += (va[k] - vb[k]) * (va[k] - vb[k]);
    ++n;
  }
  return n > 0 ? std::sqrt(sum / n) : 1e9;
}

// Exact positions at 20 Hz leave unresolved windows whose residual is at the values' rounding
// level: --json marks them, and stderr does not warn of them.
TEST_F(CliTest, VelocityMarksWindowsThatReproduceExactSamples) {
  ASSERT_EQ(Cheval("sim motion --kind car --duration 30 --rate 20 -o " + Path("m.txt")).exit_code, 0);
  RunResult run = Cheval("velocity " + Path("m.txt") + " -o " + Path("v.txt") + " --json " + Path("v.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("could not show"), std::string::npos) << run.err;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("v.json")));
  int unresolved = 0;
  for (const nlohmann::json& w : j["window_list"]) {
    if (w["accepted"] != "unresolved") continue;
    ++unresolved;
    EXPECT_TRUE(w["reproduces_samples"].get<bool>()) << w.dump();
  }
  EXPECT_GT(unresolved, 0) << "the case no longer tests anything";
}

// Slow motion at 500 Hz written to the millimetre (docs/velocity.md, "Rounded positions"): a
// staircase that is said, with its step, and fitted as motion.
TEST_F(CliTest, VelocityOfRoundedPositionsSaysSo) {
  std::ofstream measured(Path("r.txt")), truth(Path("rt.txt"));
  for (int i = 0; i < 5000; ++i) {
    const double t = 100.0 + i / 500.0;
    const double p[3] = {0.05 * std::sin(0.5 * t), 0.03 * std::cos(0.4 * t), 0.02 * std::sin(0.3 * t)};
    const double v[3] = {0.025 * std::cos(0.5 * t), -0.012 * std::sin(0.4 * t), 0.006 * std::cos(0.3 * t)};
    measured << fmt::format("{:.4f} {:.3f} {:.3f} {:.3f} 0 0 0 1\n", t, p[0], p[1], p[2]);
    truth << fmt::format("{:.4f} {} {} {} 0 0 0 1 {} {} {}\n", t, p[0], p[1], p[2], v[0], v[1], v[2]);
  }
  measured.close();
  truth.close();
  RunResult run = Cheval("velocity " + Path("r.txt") + " -o " + Path("rv.txt") + " --json " + Path("rv.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("the positions are rounded (x to 1 mm, y to 1 mm, z to 1 mm) and move less than a step a "
                         "sample: they were placed between their steps"),
            std::string::npos)
      << run.err;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("rv.json")));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(j["position_resolution_m"][c].get<double>(), 1e-3, 1e-12);
    EXPECT_TRUE(j["position_staircase"][c].get<bool>());
    EXPECT_LT(j["noise_sigma_m"][c].get<double>(), 0.2 * 1e-3 / std::sqrt(12.0));
  }
  EXPECT_EQ(j["jumps"].get<int>() + j["steps"].get<int>() + j["outliers"].get<int>(), 0);
  RunResult central = Cheval("velocity " + Path("r.txt") + " --method central -o " + Path("rc.txt"));
  ASSERT_EQ(central.exit_code, 0) << central.err;
  const double cheb = VelocityRmse(Path("rv.txt"), Path("rt.txt")), diff = VelocityRmse(Path("rc.txt"), Path("rt.txt"));
  EXPECT_LT(cheb, 0.1 * diff) << cheb << " vs central " << diff;
  // Positions not rounded say nothing of it.
  RunResult plain = Cheval("velocity " + Path("rt.txt") + " --format tumv -o " + Path("rp.txt"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.err.find("rounded"), std::string::npos) << plain.err;
}

// The same motion with white noise of 0.3 mm added before the rounding: the note gives the noise the
// fit took, sqrt(q²/12 + 0.3²) = 0.42 mm, not the rounding's 0.29 (docs/velocity.md, "Noise before
// the rounding").
TEST_F(CliTest, VelocityOfRoundedNoisyPositionsSaysTheirNoise) {
  std::ofstream measured(Path("n.txt")), truth(Path("nt.txt"));
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, 0.3e-3);
  for (int i = 0; i < 5000; ++i) {
    const double t = 100.0 + i / 500.0;
    const double p[3] = {0.05 * std::sin(0.5 * t), 0.03 * std::cos(0.4 * t), 0.02 * std::sin(0.3 * t)};
    const double v[3] = {0.025 * std::cos(0.5 * t), -0.012 * std::sin(0.4 * t), 0.006 * std::cos(0.3 * t)};
    measured << fmt::format("{:.4f} {:.3f} {:.3f} {:.3f} 0 0 0 1\n", t, p[0] + noise(rng), p[1] + noise(rng),
                            p[2] + noise(rng));
    truth << fmt::format("{:.4f} {} {} {} 0 0 0 1 {} {} {}\n", t, p[0], p[1], p[2], v[0], v[1], v[2]);
  }
  measured.close();
  truth.close();
  RunResult run = Cheval("velocity " + Path("n.txt") + " -o " + Path("nv.txt") + " --json " + Path("nv.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("nv.json")));
  EXPECT_NE(run.err.find(fmt::format("the positions are rounded (x to 1 mm: noise {:.3g} mm, y to 1 mm: noise",
                                     1e3 * j["noise_sigma_m"][0].get<double>())),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("step/sqrt(12) with any noise before it"), std::string::npos) << run.err;
  const double expected = std::sqrt(1e-6 / 12.0 + 0.09e-6);
  for (int c = 0; c < 3; ++c) {
    EXPECT_FALSE(j["position_staircase"][c].get<bool>());
    EXPECT_NEAR(j["noise_sigma_m"][c].get<double>(), expected, 0.06 * expected) << c;
  }
  EXPECT_EQ(j["stamp_noise_s"].get<double>(), 0.0);
  RunResult central = Cheval("velocity " + Path("n.txt") + " --method central -o " + Path("nc.txt"));
  ASSERT_EQ(central.exit_code, 0) << central.err;
  const double cheb = VelocityRmse(Path("nv.txt"), Path("nt.txt")), diff = VelocityRmse(Path("nc.txt"), Path("nt.txt"));
  EXPECT_LT(cheb, 0.01 * diff) << cheb << " vs central " << diff;
}

// The first column (stamps in seconds) of a TUM file, comments skipped.
std::vector<double> StampColumn(const std::string& path) {
  std::vector<double> stamps;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#') stamps.push_back(std::stod(line.substr(0, line.find(' '))));
  }
  return stamps;
}

// --at stamps the fit does not cover (before the first sample, after the last, in a gap) are left
// out and said; where none is covered, exit 3 and no output.
TEST_F(CliTest, VelocityAtStampsOutsideTheDataLeavesThemOut) {
  ASSERT_EQ(Cheval("sim motion --kind handheld --duration 10 --noise 0.0005 --gap-count 1 --gap-seconds 1 -o " +
                   Path("g.txt"))
                .exit_code,
            0);
  const std::vector<double> stamps = StampColumn(Path("g.txt"));
  ASSERT_GT(stamps.size(), 100u);
  size_t gap = 1;  // the sample after the longest step
  for (size_t i = 1; i < stamps.size(); ++i) {
    if (stamps[i] - stamps[i - 1] > stamps[gap] - stamps[gap - 1]) gap = i;
  }
  ASSERT_GT(stamps[gap] - stamps[gap - 1], 0.5);
  const double inside[3] = {stamps[10], stamps[gap / 2], stamps[gap + 20]};
  const double outside[3] = {stamps.front() - 1.0, 0.5 * (stamps[gap - 1] + stamps[gap]), stamps.back() + 2.0};
  {
    std::ofstream at(Path("at_mixed.txt"));
    at << fmt::format("{:.9f}\n{:.9f}\n{:.9f}\n{:.9f}\n{:.9f}\n{:.9f}\n", outside[0], inside[0], outside[1], inside[1],
                      inside[2], outside[2]);
    std::ofstream none(Path("at_none.txt"));
    none << fmt::format("{:.9f}\n{:.9f}\n", outside[0], outside[2]);
  }
  RunResult run = Cheval("velocity " + Path("g.txt") + " --at " + Path("at_mixed.txt") + " -o " + Path("ga.txt") +
                         " --json " + Path("ga.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("3 of its 6 stamps lie outside"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(fmt::format("the first is {:.9f} s", outside[0])), std::string::npos) << run.err;
  const std::vector<double> written = StampColumn(Path("ga.txt"));
  ASSERT_EQ(written.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(written[i], inside[i], 1e-6);
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("ga.json")));
  EXPECT_EQ(j["evaluated_at"].get<int>(), 3);
  EXPECT_EQ(j["skipped_at"].get<int>(), 3);

  RunResult none = Cheval("velocity " + Path("g.txt") + " --at " + Path("at_none.txt") + " -o " + Path("gn.txt"));
  EXPECT_EQ(none.exit_code, 3);
  EXPECT_NE(none.err.find("none of its 2 stamps lies within"), std::string::npos) << none.err;
  EXPECT_FALSE(std::filesystem::exists(Path("gn.txt")));
}

TEST_F(CliTest, VelocityAngularFromNoisyOrientations) {
  ASSERT_EQ(Cheval("sim motion --kind handheld --duration 20 --noise 0.0005 --rotation-noise 0.003 -o " + Path("m.txt") +
                   " --truth " + Path("t.txt"))
                .exit_code,
            0);
  RunResult run = Cheval("velocity " + Path("m.txt") + " --angular -o " + Path("v.txt") + " --json " + Path("v.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  RunResult central = Cheval("velocity " + Path("m.txt") + " --angular --method central -o " + Path("c.txt"));
  ASSERT_EQ(central.exit_code, 0) << central.err;
  // Columns: t x y z qx qy qz qw vx vy vz wx wy wz, in the output and in the truth.
  const double cheb = ColumnRmse(Path("v.txt"), Path("t.txt"), 11), diff = ColumnRmse(Path("c.txt"), Path("t.txt"), 11);
  EXPECT_LT(cheb, 0.2 * diff) << cheb << " vs central " << diff;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("v.json")));
  EXPECT_GE(j["angular"]["charts"].get<int>(), 1);
  EXPECT_NEAR(j["angular"]["residual_rms_rad"].get<double>(), 0.003 * std::sqrt(3.0), 0.001);
  // The output reads back as tumv with angular velocity.
  RunResult info = Cheval("info " + Path("v.txt"));
  EXPECT_EQ(info.exit_code, 0) << info.err;
  // Positions only: --angular has nothing to differentiate.
  std::ofstream(Path("p.csv")) << "1,0,0,0\n2,1,0,0\n3,2,0,0\n";
  RunResult no_orientation =
      Cheval("velocity " + Path("p.csv") + " --format csv --columns t,px,py,pz --angular -o " + Path("out.txt"));
  EXPECT_EQ(no_orientation.exit_code, 1);
  EXPECT_EQ(no_orientation.err, "cheval: error: --angular needs orientations, but the trajectory has positions only\n");
  EXPECT_EQ(Cheval("velocity " + Path("m.txt") + " --angular --method savgol -o " + Path("out.txt")).exit_code, 1);
  EXPECT_FALSE(fs::exists(Path("out.txt")));
}

TEST_F(CliTest, VelocityBadInput) {
  std::ofstream(Path("one.txt")) << "1 0 0 0 0 0 0 1\n";
  RunResult one = Cheval("velocity " + Path("one.txt") + " -o " + Path("out.txt"));
  EXPECT_EQ(one.exit_code, 3);
  EXPECT_EQ(one.err, "cheval: error: a fit needs at least 2 samples, got 1\n");
  std::ofstream(Path("same.txt")) << "1 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n1 2 0 0 0 0 0 1\n";
  RunResult same = Cheval("velocity " + Path("same.txt") + " -o " + Path("out.txt"));
  EXPECT_EQ(same.exit_code, 3);
  EXPECT_EQ(same.err, "cheval: error: all 3 stamps are equal: there is no time to fit over\n");
  ASSERT_EQ(Cheval("sim motion --duration 1 --rate 20 -o " + Path("short.txt")).exit_code, 0);
  RunResult degree = Cheval("velocity " + Path("short.txt") + " --degree 50 -o " + Path("out.txt"));
  EXPECT_EQ(degree.exit_code, 3);
  EXPECT_NE(degree.err.find("degree 50 needs at least 51 distinct stamps per window"), std::string::npos);
  EXPECT_EQ(Cheval("velocity " + Path("short.txt") + " --method magic").exit_code, 1);
  EXPECT_EQ(Cheval("velocity " + Path("short.txt") + " --degree lots").exit_code, 1);
  // Degree 0 is a constant: a velocity of zero whatever the motion, refused rather than written.
  RunResult constant = Cheval("velocity " + Path("short.txt") + " --degree 0 -o " + Path("out.txt"));
  EXPECT_EQ(constant.exit_code, 1);
  EXPECT_NE(constant.err.find("--degree must be >= 1 for a velocity"), std::string::npos) << constant.err;
  EXPECT_EQ(Cheval("velocity " + Path("short.txt") + " --method central --at " + Path("short.txt")).exit_code, 1);
  EXPECT_EQ(Cheval("velocity " + cheval::testing::FixturePath("bad/nan.txt") + " -o " + Path("out.txt")).exit_code, 2);
  EXPECT_FALSE(fs::exists(Path("out.txt")));
}

TEST_F(CliTest, InfoReadsSharedDataWithStatedCounts) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string root = cheval::testing::SharedDataDir();
  RunResult run = Cheval("info " + root + "/evo/fr2_desk_groundtruth.txt " + root + "/evo/V102_groundtruth.csv --json " +
                   Path("all.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json all = nlohmann::json::parse(Slurp(Path("all.json")));
  ASSERT_TRUE(all.is_array());
  EXPECT_EQ(all[0]["poses"], 20957);     // the pose count ../shared/data/evo/SOURCE.md states
  EXPECT_EQ(all[0]["duplicate_stamps"], 1);  // stamp 1311868229.5760 appears twice (lines 10862-10863)
  EXPECT_EQ(all[1]["poses"], 16702);
  EXPECT_EQ(all[1]["has_velocity"], true);
  // Last minus first stamp, 1403715608412143104 - 1403715524907143168 ns (the data's SOURCE.md rounds to 83.50 s).
  EXPECT_DOUBLE_EQ(all[1]["duration_s"].get<double>(), 83.504999936);
}

}  // namespace
}  // namespace cheval

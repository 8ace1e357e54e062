// `cheval compress` and `cheval sample` end to end: the model reproduces the simulator's truth better
// than the noisy samples it came from, the report's numbers are what sampling gives back, the
// tolerance is met or refused, real EuRoC ground truth compresses, and every bad input has its
// documented exit code, one-line message and no output file.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

// Stamps (as text) and positions of the rows of a TUM file (8 or more columns).
struct Rows {
  std::vector<std::string> stamps;
  std::vector<std::array<double, 3>> positions;
};

Rows ReadRows(const std::string& path) {
  Rows rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string stamp;
    std::array<double, 3> p{};
    fields >> stamp >> p[0] >> p[1] >> p[2];
    rows.stamps.push_back(stamp);
    rows.positions.push_back(p);
  }
  return rows;
}

// Largest and RMS Euclidean distance between the positions of two files, row by row.
std::pair<double, double> Distance(const Rows& a, const Rows& b) {
  double max = 0, sum = 0;
  for (size_t i = 0; i < a.positions.size(); ++i) {
    double squared = 0;
    for (int k = 0; k < 3; ++k) squared += std::pow(a.positions[i][k] - b.positions[i][k], 2);
    max = std::max(max, std::sqrt(squared));
    sum += squared;
  }
  return {max, std::sqrt(sum / static_cast<double>(a.positions.size()))};
}

class CompressCliTest : public CliTest {
 protected:
  // 20 s of the simulated drone at 200 Hz with 0.5 mm noise per axis (and `extra` options).
  void Simulate(const std::string& extra = "") const {
    const RunResult sim = Cheval("sim motion --kind drone --seed 1 --duration 20 --noise 0.0005 " + extra + " -o " +
                                 Path("m.txt") + " --truth " + Path("truth.txt"));
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
};

TEST_F(CompressCliTest, ModelIsCloserToTheTruthThanTheSamplesAndReportsWhatSamplingGives) {
  Simulate();
  const RunResult run = Cheval("compress " + Path("m.txt") + " -o " + Path("model.json") + " --json " + Path("r.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("compression"), std::string::npos);
  EXPECT_NE(run.out.find("(orientation is not stored)"), std::string::npos);
  const nlohmann::json r = nlohmann::json::parse(Slurp(Path("r.json")));
  for (const char* key : {"input", "model", "tolerance_m", "segments", "windows", "degrees", "input_numbers",
                          "model_values", "model_numbers", "compression_ratio", "max_error_m", "rms_error_m",
                          "worst_stamp", "noise_sigma_m", "automatic", "seconds"}) {
    EXPECT_TRUE(r.contains(key)) << key;
  }
  EXPECT_EQ(r["input_numbers"], 3 * 4001);
  EXPECT_TRUE(r["tolerance_m"].is_null());
  EXPECT_GT(r["compression_ratio"].get<double>(), 20.0);
  EXPECT_EQ(r["model"]["bytes"], fs::file_size(Path("model.json")));
  // The error at the samples is the noise: RMS ≈ σ·sqrt(3) = 0.87 mm.
  EXPECT_NEAR(r["rms_error_m"].get<double>(), 0.0005 * std::sqrt(3.0), 0.0001);

  // Sampled at the measured stamps, the distances to the samples are the reported errors.
  const RunResult at_samples =
      Cheval("sample " + Path("model.json") + " --at " + Path("m.txt") + " -o " + Path("s.txt"));
  ASSERT_EQ(at_samples.exit_code, 0) << at_samples.err;
  const Rows measured = ReadRows(Path("m.txt")), sampled = ReadRows(Path("s.txt"));
  ASSERT_EQ(sampled.stamps, measured.stamps);
  const auto [max, rms] = Distance(sampled, measured);
  EXPECT_NEAR(max, r["max_error_m"].get<double>(), 1e-12);
  EXPECT_NEAR(rms, r["rms_error_m"].get<double>(), 1e-12);
  EXPECT_NE(Slurp(Path("s.txt")).find(" 0 0 0 1\n"), std::string::npos);  // identity orientation

  // At the truth's stamps the model is nearer the truth than the samples are (noise averaged out).
  const RunResult at_truth =
      Cheval("sample " + Path("model.json") + " --at " + Path("truth.txt") + " -o " + Path("t.txt"));
  ASSERT_EQ(at_truth.exit_code, 0) << at_truth.err;
  const auto [truth_max, truth_rms] = Distance(ReadRows(Path("t.txt")), ReadRows(Path("truth.txt")));
  EXPECT_LT(truth_rms, 0.5 * 0.0005);
  EXPECT_LT(truth_max, 0.0005 * 3);

  // --rate: every 1/50 s from the first stamp to the last, 20 s -> 1001 rows.
  const RunResult rate = Cheval("sample " + Path("model.json") + " --rate 50 -o " + Path("g.txt"));
  ASSERT_EQ(rate.exit_code, 0) << rate.err;
  const Rows grid = ReadRows(Path("g.txt"));
  ASSERT_EQ(grid.stamps.size(), 1001u);
  EXPECT_EQ(grid.stamps.front(), measured.stamps.front());
  EXPECT_EQ(grid.stamps[1], "1403636580.020000000");
  EXPECT_EQ(grid.stamps.back(), measured.stamps.back());
}

TEST_F(CompressCliTest, ToleranceIsMetOrRefusedWithNoFile) {
  Simulate();
  ASSERT_EQ(
      Cheval("compress " + Path("m.txt") + " -o " + Path("auto.json") + " --json " + Path("auto.r.json")).exit_code, 0);
  const RunResult met = Cheval("compress " + Path("m.txt") + " -o " + Path("tol.json") + " --tolerance 0.005 --json " +
                               Path("tol.r.json"));
  ASSERT_EQ(met.exit_code, 0) << met.err;
  const nlohmann::json automatic = nlohmann::json::parse(Slurp(Path("auto.r.json")));
  const nlohmann::json tolerance = nlohmann::json::parse(Slurp(Path("tol.r.json")));
  EXPECT_EQ(tolerance["tolerance_m"], 0.005);
  EXPECT_LE(tolerance["max_error_m"].get<double>(), 0.005);
  EXPECT_GT(tolerance["compression_ratio"].get<double>(), automatic["compression_ratio"].get<double>());
  EXPECT_NE(Slurp(Path("tol.json")).find("\"tolerance\": 0.005,"), std::string::npos);

  // 0.5 mm is σ: most samples lie farther than that from any smooth path.
  const RunResult refused = Cheval("compress " + Path("m.txt") + " -o " + Path("no.json") + " --tolerance 0.0005");
  EXPECT_EQ(refused.exit_code, 3);
  EXPECT_EQ(refused.err.rfind("cheval: error: cannot meet the tolerance of 0.0005 m: the most accurate model cheval can "
                              "build from these samples (N^2/m <= 8 and degree <= 400 per window, windows down to 24 "
                              "samples) has a max error of ",
                              0),
            0u)
      << refused.err;
  EXPECT_NE(refused.err.find("a smaller max error means following the noise\n"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(Path("no.json")));
}

TEST_F(CompressCliTest, GapsAreSkippedByRateAndRefusedByAt) {
  Simulate("--gap-count 1 --gap-seconds 2");
  ASSERT_EQ(Cheval("compress " + Path("m.txt") + " -o " + Path("model.json") + " --json " + Path("r.json")).exit_code,
            0);
  EXPECT_EQ(nlohmann::json::parse(Slurp(Path("r.json")))["segments"], 2);
  const RunResult rate = Cheval("sample " + Path("model.json") + " --rate 10 -o " + Path("g.txt"));
  ASSERT_EQ(rate.exit_code, 0) << rate.err;
  // 201 grid stamps over 20 s, about 20 of them in the 2 s gap.
  const size_t rows = ReadRows(Path("g.txt")).stamps.size();
  EXPECT_GE(rows, 180u);
  EXPECT_LE(rows, 182u);
  // The truth has stamps in the gap: refused, naming the first one, and nothing written.
  const RunResult gap = Cheval("sample " + Path("model.json") + " --at " + Path("truth.txt") + " -o " + Path("t.txt"));
  EXPECT_EQ(gap.exit_code, 3);
  EXPECT_EQ(gap.err.rfind("cheval: error: --at " + Path("truth.txt") + ": stamp #", 0), 0u) << gap.err;
  EXPECT_NE(gap.err.find(" s) is inside a gap of the model: no samples from "), std::string::npos) << gap.err;
  EXPECT_FALSE(fs::exists(Path("t.txt")));
  std::ofstream(Path("early.txt")) << "1403636579.5\n";
  const RunResult early =
      Cheval("sample " + Path("model.json") + " --at " + Path("early.txt") + " -o " + Path("t.txt"));
  EXPECT_EQ(early.exit_code, 3);
  EXPECT_EQ(early.err, "cheval: error: --at " + Path("early.txt") +
                           ": stamp #1 (1403636579.500000000 s) is outside the modelled time range "
                           "1403636580.000000000 s to 1403636600.000000000 s\n");
  EXPECT_FALSE(fs::exists(Path("t.txt")));
}

TEST_F(CompressCliTest, BadInputHasItsExitCodeAndLeavesNoFile) {
  std::ofstream(Path("one.txt")) << "1 0 0 0 0 0 0 1\n";
  const RunResult one = Cheval("compress " + Path("one.txt") + " -o " + Path("out.json"));
  EXPECT_EQ(one.exit_code, 3);
  EXPECT_EQ(one.err, "cheval: error: a fit needs at least 2 samples, got 1\n");
  std::ofstream(Path("same.txt")) << "1 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n1 2 0 0 0 0 0 1\n";
  const RunResult same = Cheval("compress " + Path("same.txt") + " -o " + Path("out.json"));
  EXPECT_EQ(same.exit_code, 3);
  EXPECT_EQ(same.err, "cheval: error: all 3 stamps are equal: there is no time to fit over\n");
  for (const char* bad : {"0", "-1"}) {
    const RunResult run = Cheval("compress " + Path("same.txt") + " -o " + Path("out.json") + " --tolerance " + bad);
    EXPECT_EQ(run.exit_code, 1) << bad;
    EXPECT_EQ(run.err,
              std::string("cheval: error: --tolerance must be a positive number of metres, got ") + bad + "\n");
  }
  // Not a finite number: refused as the flag's text, before the library sees it (docs/cli.md, "Option values").
  for (const char* bad : {"nan", "inf"}) {
    const RunResult run = Cheval("compress " + Path("same.txt") + " -o " + Path("out.json") + " --tolerance " + bad);
    EXPECT_EQ(run.exit_code, 1) << bad;
    EXPECT_EQ(run.err, std::string("cheval: error: --tolerance: must be a finite number, got ") + bad +
                           "\nRun 'cheval --help' for usage.\n");
  }
  EXPECT_EQ(Cheval("compress " + Path("same.txt") + " -o " + Path("out.json") + " --tolerance abc").exit_code, 1);
  EXPECT_EQ(Cheval("compress " + Path("same.txt")).exit_code, 1);  // -o is required
  const RunResult unreadable =
      Cheval("compress " + cheval::testing::FixturePath("bad/nan.txt") + " -o " + Path("out.json"));
  EXPECT_EQ(unreadable.exit_code, 2);
  EXPECT_FALSE(fs::exists(Path("out.json")));

  // sample: options, then malformed and missing models.
  std::ofstream(Path("model.json")) << "{\"format\": \"cheval-trajectory-model\", \"version\": 7}\n";
  for (const char* bad : {"0", "-2"}) {
    const RunResult run =
        Cheval("sample " + Path("model.json") + " --rate " + std::string(bad) + " -o " + Path("s.txt"));
    EXPECT_EQ(run.exit_code, 1) << bad;
    EXPECT_EQ(run.err, std::string("cheval: error: --rate must be a positive number of Hz, got ") + bad + "\n");
  }
  const RunResult nan_rate = Cheval("sample " + Path("model.json") + " --rate nan -o " + Path("s.txt"));
  EXPECT_EQ(nan_rate.exit_code, 1);
  EXPECT_EQ(nan_rate.err, "cheval: error: --rate: must be a finite number, got nan\nRun 'cheval --help' for usage.\n");
  const RunResult neither = Cheval("sample " + Path("model.json") + " -o " + Path("s.txt"));
  EXPECT_EQ(neither.exit_code, 1);
  EXPECT_EQ(neither.err, "cheval: error: sample needs --rate HZ or --at FILE\n");
  EXPECT_EQ(
      Cheval("sample " + Path("model.json") + " --rate 5 --at " + Path("one.txt") + " -o " + Path("s.txt")).exit_code,
      1);
  const RunResult version = Cheval("sample " + Path("model.json") + " --rate 5 -o " + Path("s.txt"));
  EXPECT_EQ(version.exit_code, 2);
  EXPECT_EQ(version.err,
            Path("model.json") + ":0:0: error: version: expected 1 or 2 (the versions this cheval reads), got 7\n");
  std::ofstream(Path("broken.json")) << "{\"format\": \n";
  const RunResult broken = Cheval("sample " + Path("broken.json") + " --rate 5 -o " + Path("s.txt"));
  EXPECT_EQ(broken.exit_code, 2);
  EXPECT_EQ(broken.err.rfind(Path("broken.json") + ":2:1: error: expected JSON (a cheval trajectory model): ", 0), 0u)
      << broken.err;
  const RunResult missing = Cheval("sample " + Path("nope.json") + " --rate 5 -o " + Path("s.txt"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err, Path("nope.json") + ":0:0: error: cannot open file: No such file or directory\n");
  EXPECT_FALSE(fs::exists(Path("s.txt")));
}

TEST_F(CompressCliTest, EurocGroundTruthCompresses) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string euroc = cheval::testing::SharedDataDir() + "/ov_data/euroc_mav/V1_02_medium.csv";
  const RunResult automatic = Cheval("compress " + euroc + " -o " + Path("a.json") + " --json " + Path("a.r.json"));
  ASSERT_EQ(automatic.exit_code, 0) << automatic.err;
  const nlohmann::json a = nlohmann::json::parse(Slurp(Path("a.r.json")));
  EXPECT_EQ(a["input"]["poses"], 16702);  // the pose count ../shared/data/ov_data/SOURCE.md states
  // EuRoC's ground truth is smooth to ~2 µm (estimated noise), so the automatic fit keeps detail:
  // measured ratio 2.7, max error 0.21 mm.
  EXPECT_GT(a["compression_ratio"].get<double>(), 2.0);
  EXPECT_LT(a["max_error_m"].get<double>(), 0.001);
  const RunResult millimetre =
      Cheval("compress " + euroc + " -o " + Path("t.json") + " --tolerance 0.001 --json " + Path("t.r.json"));
  ASSERT_EQ(millimetre.exit_code, 0) << millimetre.err;
  const nlohmann::json t = nlohmann::json::parse(Slurp(Path("t.r.json")));
  EXPECT_LE(t["max_error_m"].get<double>(), 0.001);
  EXPECT_GT(t["compression_ratio"].get<double>(), 5.0 * a["compression_ratio"].get<double>());  // measured 18.9
}

}  // namespace
}  // namespace cheval

// `cheval sim quadrotor` and `cheval estimate quadrotor` end to end: the documented files, the
// printed figures and the JSON keys of issue 5, and every bad input with its documented exit code.
#include <filesystem>
#include <fstream>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace cheval {
namespace {

namespace fs = std::filesystem;
using cheval::testing::CliTest;
using cheval::testing::RunResult;
using cheval::testing::Slurp;

// The numbers of a CSV text with a header line, row by row.
std::vector<std::vector<double>> CsvRows(const std::string& text) {
  std::vector<std::vector<double>> rows;
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);  // header
  while (std::getline(lines, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) row.push_back(std::stod(field));
    rows.push_back(std::move(row));
  }
  return rows;
}

TEST_F(CliTest, SimulateThenEstimateFromTheFolder) {
  RunResult sim = Cheval("sim quadrotor --scenario figure8 --seed 2 --duration 3 -o " + Path("flight"));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  for (const char* file : {"vehicle.json", "landmarks.csv", "measurements.csv", "initial.csv", "truth.csv"}) {
    EXPECT_TRUE(fs::exists(dir_ / "flight" / file)) << file;
  }
  RunResult run = Cheval("estimate quadrotor --data " + Path("flight") + " --json " + Path("r.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("rotor error %"), std::string::npos) << run.out;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("r.json")));
  for (const char* key : {"states", "segments", "degree", "seconds", "rotor_error_rpm", "rotor_error_percent",
                          "position_rmse_m", "rotation_rmse_deg", "velocity_rmse_mps"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  ASSERT_EQ(j["rotor_error_percent"].size(), 4u);
  EXPECT_EQ(j["degree"].get<int>(), 4);  // the defaults: degree 4, 0.2 s segments over the 3 s flight
  EXPECT_EQ(j["segments"].get<int>(), 15);
  EXPECT_EQ(j["states"].get<int>(), 61);
  for (const auto& e : j["rotor_error_percent"]) EXPECT_LT(e.get<double>(), 1.5);
  EXPECT_LT(j["position_rmse_m"].get<double>(), 0.02);

  // -o: the estimated states in truth.csv's layout, at the truth's times; the position RMSE computed
  // from the two files is the one the JSON reports.
  RunResult with_states = Cheval("estimate quadrotor --data " + Path("flight") + " -o " + Path("states.csv"));
  ASSERT_EQ(with_states.exit_code, 0) << with_states.err;
  const std::vector<std::vector<double>> truth = CsvRows(Slurp(dir_ / "flight" / "truth.csv"));
  const std::vector<std::vector<double>> states = CsvRows(Slurp(Path("states.csv")));
  const auto header = [](const std::string& text) { return text.substr(0, text.find('\n')); };
  EXPECT_EQ(header(Slurp(Path("states.csv"))), header(Slurp(dir_ / "flight" / "truth.csv")));
  ASSERT_EQ(states.size(), truth.size());
  double p2 = 0;
  for (size_t i = 0; i < states.size(); ++i) {
    ASSERT_EQ(states[i].size(), 18u);
    EXPECT_EQ(states[i][0], truth[i][0]);
    for (int k = 1; k <= 3; ++k) p2 += (states[i][k] - truth[i][k]) * (states[i][k] - truth[i][k]);
  }
  EXPECT_NEAR(std::sqrt(p2 / static_cast<double>(states.size())), j["position_rmse_m"].get<double>(), 1e-9);

  // Without truth.csv the estimate still runs and prints no errors; -o then samples every 10 ms.
  fs::remove(dir_ / "flight" / "truth.csv");
  RunResult no_truth = Cheval("estimate quadrotor --data " + Path("flight") + " --json " + Path("n.json") + " -o " +
                              Path("s2.csv"));
  ASSERT_EQ(no_truth.exit_code, 0) << no_truth.err;
  EXPECT_NE(no_truth.out.find("no truth.csv"), std::string::npos);
  EXPECT_FALSE(nlohmann::json::parse(Slurp(Path("n.json"))).contains("rotor_error_percent"));
  const std::vector<std::vector<double>> sampled = CsvRows(Slurp(Path("s2.csv")));
  ASSERT_GE(sampled.size(), 250u);  // ~3 s of frames at 100 Hz
  EXPECT_NEAR(sampled[1][0] - sampled[0][0], 0.01, 1e-12);
}

// --vehicle replaces the folder's vehicle: a 20 % heavier (wrong) mass makes the rotor speeds come
// out ~sqrt(1.2) - 1 ≈ 9.5 % too high, far above the < 1.5 % of the right vehicle.
TEST_F(CliTest, EstimateWithAnotherVehicleFile) {
  ASSERT_EQ(Cheval("sim quadrotor --scenario hover --duration 2 -o " + Path("f")).exit_code, 0);
  std::string text = Slurp(dir_ / "f" / "vehicle.json");
  const std::string from = "\"mass_kg\": 1.0";
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << text;
  std::ofstream(Path("heavy.json")) << text.replace(at, from.size(), "\"mass_kg\": 1.2");
  RunResult run = Cheval("estimate quadrotor --data " + Path("f") + " --vehicle " + Path("heavy.json") + " --json " +
                         Path("r.json"));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(Slurp(Path("r.json")));
  for (const auto& e : j["rotor_error_percent"]) EXPECT_NEAR(e.get<double>(), 9.5, 1.0);
}

TEST_F(CliTest, EstimateFromScenarioWithOptions) {
  RunResult run = Cheval("estimate quadrotor --scenario hover --seed 3 --duration 2 --degree 8 --segment 0.5");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("segments            4"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("states              33"), std::string::npos) << run.out;
}

TEST_F(CliTest, EstimateBadInput) {
  RunResult unknown = Cheval("estimate quadrotor --scenario loop");
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.err.find("unknown scenario 'loop'"), std::string::npos) << unknown.err;
  EXPECT_EQ(Cheval("estimate quadrotor").exit_code, 1);  // neither --scenario nor --data
  EXPECT_EQ(Cheval("estimate quadrotor --scenario hover --data x").exit_code, 1);
  EXPECT_EQ(Cheval("estimate quadrotor --scenario hover --degree 1").exit_code, 1);

  RunResult missing = Cheval("estimate quadrotor --data " + Path("nowhere"));
  EXPECT_EQ(missing.exit_code, 2);

  ASSERT_EQ(Cheval("sim quadrotor --scenario hover --duration 1 -o " + Path("f")).exit_code, 0);
  fs::remove(dir_ / "f" / "initial.csv");
  RunResult no_initial = Cheval("estimate quadrotor --data " + Path("f"));
  EXPECT_EQ(no_initial.exit_code, 2);
  EXPECT_NE(no_initial.err.find("initial.csv:0:0: error: cannot open"), std::string::npos) << no_initial.err;

  // A measurement after the last initial pose: outside the interval the front end covers.
  ASSERT_EQ(Cheval("sim quadrotor --scenario hover --duration 1 -o " + Path("g")).exit_code, 0);
  std::ofstream(dir_ / "g" / "measurements.csv", std::ios::app) << "5.0,0,320,240\n";
  RunResult outside = Cheval("estimate quadrotor --data " + Path("g"));
  EXPECT_EQ(outside.exit_code, 3);
  EXPECT_NE(outside.err.find("do not cover the measurement interval"), std::string::npos) << outside.err;

  // A non-physical vehicle: the folder's own vehicle file with a negative mass.
  std::string text = Slurp(dir_ / "g" / "vehicle.json");
  const size_t at = text.find("\"mass_kg\": 1.0");
  ASSERT_NE(at, std::string::npos) << text;
  std::ofstream(Path("v.json")) << text.replace(at, std::string("\"mass_kg\": 1.0").size(), "\"mass_kg\": -1.0");
  RunResult vehicle = Cheval("sim quadrotor --scenario hover --vehicle " + Path("v.json") + " -o " + Path("h"));
  EXPECT_EQ(vehicle.exit_code, 2);
  EXPECT_NE(vehicle.err.find("\"mass_kg\" must be a finite number > 0"), std::string::npos) << vehicle.err;
  EXPECT_FALSE(fs::exists(dir_ / "h"));
}

}  // namespace
}  // namespace cheval

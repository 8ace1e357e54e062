// The KITTI drift figures docs/evaluation.md publishes ("Worked example on the evo files"), asserted on
// the shared data with the documented command: KITTI 00, ORB-SLAM2 0.6997 % and 0.002536 deg/m,
// S-PTAM 1.4870 % and 0.005578 deg/m, 3283 segments. (python/tests/test_first_principles.py computes
// the same figures from the devkit's definition in numpy, independently of cheval.) Needs the shared
// data: skipped without it, a failure in CI (tests/support/test_data.h).
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/test_data.h"
#include "cli_runner.h"

namespace cheval {
namespace {

class KittiDriftCliTest : public testing::CliTest {};

TEST_F(KittiDriftCliTest, DocumentedFiguresOnKitti00) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string evo = testing::SharedDataDir() + "/evo";
  const testing::RunResult run = Shell(fmt::format(
      "cd {} && {} rpe KITTI_00_gt.txt KITTI_00_ORB.txt KITTI_00_SPTAM.txt --delta 100 --delta-unit meters "
      "--kitti-drift --json {}",
      evo, CHEVAL_EXE, Path("r.json")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // The lines as docs/evaluation.md prints them (4 and 6 decimals).
  for (const char* line : {"KITTI drift over 100..800 m of reference path (3283 segments): translation 0.6997 %, "
                           "rotation 0.002536 deg/m",
                           "KITTI drift over 100..800 m of reference path (3283 segments): translation 1.4870 %, "
                           "rotation 0.005578 deg/m"}) {
    EXPECT_NE(run.out.find(line), std::string::npos) << line << "\n" << run.out;
  }
  // The JSON to the documented rounding: within half a unit of the last printed digit.
  const nlohmann::json j = nlohmann::json::parse(testing::Slurp(Path("r.json")));
  ASSERT_EQ(j.size(), 2u);
  const double translation[] = {0.6997, 1.4870}, rotation[] = {0.002536, 0.005578};
  for (size_t k = 0; k < 2; ++k) {
    const nlohmann::json& drift = j[k]["drift"];
    EXPECT_EQ(drift["segments"], 3283) << k;
    EXPECT_NEAR(drift["translation_percent"].get<double>(), translation[k], 0.5e-4) << k;
    EXPECT_NEAR(drift["rotation_deg_per_m"].get<double>(), rotation[k], 0.5e-6) << k;
    // The eight lengths' segments add up to the total.
    int segments = 0;
    for (const nlohmann::json& length : drift["lengths"]) segments += length["segments"].get<int>();
    EXPECT_EQ(segments, 3283) << k;
  }
}

}  // namespace
}  // namespace cheval

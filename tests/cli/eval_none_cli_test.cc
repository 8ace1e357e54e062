// What the evaluation commands print when a figure does not exist: `rpe --kitti-drift` on a path
// shorter than 100 m says none and writes JSON null (not 0 %), and `ase` on a reference whose
// orientations are all the identity warns once and leaves the rotation part out unless
// --ref-has-orientation. On the shared TUM files of evo's examples (skipped without them).
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/test_data.h"
#include "cli_runner.h"

namespace cheval {
namespace {

class EvalNoneCliTest : public testing::CliTest {};

TEST_F(EvalNoneCliTest, KittiDriftOnAShortPathIsNone) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string evo = testing::SharedDataDir() + "/evo/";
  // fr2/desk: about 18 m of path, no 100 m segment.
  const testing::RunResult run = Cheval(fmt::format("rpe {0}fr2_desk_groundtruth.txt {0}fr2_desk_ORB.txt -a --kitti-drift "
                                                    "--json {1}",
                                                    evo, Path("r.json")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("KITTI drift over 100..800 m of reference path: none (path shorter than 100 m)"),
            std::string::npos)
      << run.out;
  EXPECT_EQ(run.out.find("0.0000 %"), std::string::npos) << run.out;
  const nlohmann::json drift = nlohmann::json::parse(testing::Slurp(Path("r.json")))["drift"];
  EXPECT_EQ(drift["segments"], 0);
  EXPECT_TRUE(drift["translation_percent"].is_null()) << drift;
  EXPECT_TRUE(drift["rotation_deg_per_m"].is_null()) << drift;
  for (const nlohmann::json& length : drift["lengths"]) EXPECT_TRUE(length["translation_percent"].is_null());
}

TEST_F(EvalNoneCliTest, AseOnAnIdentityOrientationReferenceIsPositionOnlyWithOneWarning) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string evo = testing::SharedDataDir() + "/evo/";
  // The reference's positions with identity quaternions, as `cheval velocity` writes a position-only
  // source (the quaternion columns skipped by the column map).
  const std::string reference = Path("gt.tumv"), estimate = Path("est.tumv");
  ASSERT_EQ(Cheval(fmt::format("velocity {}fr2_desk_groundtruth.txt --format csv --columns t,px,py,pz,_,_,_,_ -o {} -q",
                               evo, reference))
                .exit_code,
            0);
  ASSERT_EQ(Cheval(fmt::format("velocity {}fr2_desk_ORB.txt -o {} -q", evo, estimate)).exit_code, 0);
  const std::string files = reference + " " + estimate + " -a";
  const testing::RunResult run = Cheval(fmt::format("ase {} --json {}", files, Path("a.json")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("warning: the reference's orientations are all the identity"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--ref-has-orientation"), std::string::npos) << run.err;
  const nlohmann::json a = nlohmann::json::parse(testing::Slurp(Path("a.json")));
  EXPECT_FALSE(a["parts"].contains("rotation")) << a["parts"];
  const testing::RunResult kept = Cheval(fmt::format("ase {} --ref-has-orientation --json {}", files, Path("b.json")));
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  EXPECT_EQ(kept.err.find("warning: the reference's orientations"), std::string::npos) << kept.err;
  const nlohmann::json b = nlohmann::json::parse(testing::Slurp(Path("b.json")));
  EXPECT_TRUE(b["parts"].contains("rotation"));
  EXPECT_GT(b["stats"]["rmse"].get<double>(), a["stats"]["rmse"].get<double>());
}

}  // namespace
}  // namespace cheval

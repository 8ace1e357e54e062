// evo's flag spellings (docs/cli.md, "evo's flags"): each evo command line gives the JSON of its
// cheval spelling, contradictions and unknown flags are exit 1 with the cheval spelling and
// `cheval COMMAND --help`. On the shared TUM files of evo's examples (skipped without them).
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/test_data.h"
#include "cli_runner.h"

namespace cheval {
namespace {

class EvoFlagsCliTest : public testing::CliTest {
 protected:
  // The JSON text of `cheval COMMAND REF EST ARGS --json FILE` (the run must succeed).
  std::string Json(const std::string& command, const std::string& args, const std::string& name) {
    const std::string evo = testing::SharedDataDir() + "/evo/";
    const testing::RunResult run =
        Cheval(fmt::format("{} {}fr2_desk_groundtruth.txt {}fr2_desk_ORB_kf_mono.txt {} --json {}", command, evo, evo,
                           args, Path(name)));
    EXPECT_EQ(run.exit_code, 0) << command << " " << args << "\n" << run.err;
    return testing::Slurp(Path(name));
  }
};

struct Spelling {
  const char* command;
  const char* evo;
  const char* cheval;
};

TEST_F(EvoFlagsCliTest, EvoSpellingsGiveTheJsonOfTheChevalSpellings) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::vector<Spelling> cases = {
      {"ape", "-va", "--align se3"},
      {"ape", "-as", "--align sim3"},
      {"ape", "-a -s", "--align sim3"},
      {"ape", "-vas", "--align sim3"},
      {"ape", "--align --correct_scale", "--align sim3"},
      {"ape", "-s", "--align scale"},
      {"ape", "--correct_scale", "--align scale"},
      {"ape", "--align_origin", "--align origin"},
      {"ape", "-a --n_to_align 50", "--align se3 --n-align 50"},
      {"ape", "-a --t_max_diff 0.02 --t_offset 0.001", "--align se3 --t-max-diff 0.02 --t-offset 0.001"},
      {"ape", "-as --pose_relation angle_deg", "--align sim3 -r angle_deg"},
      {"ape", "-a --align se3", "--align se3"},
      {"rpe", "-as -d 10 -u m --all_pairs", "--align sim3 --delta 10 --delta-unit meters --all-pairs"},
      {"rpe", "--delta 5 --delta_unit f -r rot_part", "--delta 5 --delta-unit frames --relation rot_part"},
      {"ase", "-va --pose-only", "--align se3 --pose-only"},
  };
  int k = 0;
  for (const Spelling& c : cases) {
    const std::string evo = Json(c.command, c.evo, fmt::format("evo{}.json", k));
    const std::string cheval = Json(c.command, c.cheval, fmt::format("cheval{}.json", k));
    ASSERT_FALSE(cheval.empty()) << c.cheval;
    EXPECT_EQ(evo, cheval) << c.command << " " << c.evo << " vs " << c.cheval;
    ++k;
  }
  // And the alignment really differs between the spellings (the test would not see a flag ignored).
  EXPECT_NE(Json("ape", "-a", "a.json"), Json("ape", "-as", "as.json"));
}

TEST_F(EvoFlagsCliTest, InfoTakesFullCheck) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string file = testing::SharedDataDir() + "/evo/fr2_desk_groundtruth.txt";
  ASSERT_EQ(Cheval(fmt::format("info {} --full_check --json {}", file, Path("a.json"))).exit_code, 0);
  ASSERT_EQ(Cheval(fmt::format("info {} --json {}", file, Path("b.json"))).exit_code, 0);
  EXPECT_EQ(testing::Slurp(Path("a.json")), testing::Slurp(Path("b.json")));
}

TEST_F(EvoFlagsCliTest, ContradictionsAndUnknownFlagsSayTheChevalSpelling) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string evo = testing::SharedDataDir() + "/evo/";
  const std::string files = evo + "fr2_desk_groundtruth.txt " + evo + "fr2_desk_ORB_kf_mono.txt";
  struct Case {
    std::string args;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases = {
      {"ape " + files + " -a --align sim3", {"--align sim3 contradicts", "--align se3"}},
      {"ape " + files + " -a --align_origin", {"--align_origin with -a/-s"}},
      {"ape " + files + " --t_max_dif 0.02", {"did you mean --t-max-diff?", "Run 'cheval ape --help'"}},
      {"ape " + files + " -p", {"-p is evo's spelling; cheval: no plot window: cheval report", "cheval ape --help"}},
      {"rpe " + files + " --delta_units m", {"did you mean --delta-unit?", "Run 'cheval rpe --help'"}},
      {"ase " + files + " --zzzzzzzz", {"the argument --zzzzzzzz was not expected", "Run 'cheval ase --help'"}},
  };
  for (const Case& c : cases) {
    const testing::RunResult run = Cheval(c.args);
    EXPECT_EQ(run.exit_code, 1) << c.args << "\n" << run.err;
    for (const std::string& text : c.expected) {
      EXPECT_NE(run.err.find(text), std::string::npos) << c.args << ": expected " << text << " in\n" << run.err;
    }
  }
}

}  // namespace
}  // namespace cheval

namespace cheval {
namespace {

class LabelCliTest : public testing::CliTest {};

// --label names each estimate in order in the tables and the JSON; the default is the file name.
TEST_F(LabelCliTest, LabelsInOrderElseTheFileName) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::string evo = testing::SharedDataDir() + "/evo/";
  const std::string files = evo + "fr2_desk_groundtruth.txt " + evo + "fr2_desk_ORB.txt " + evo + "fr2_desk_ORB_kf_mono.txt -as";
  const testing::RunResult run =
      Cheval(fmt::format("ape {} --label ORB --label 'ORB mono' --json {}", files, Path("l.json")));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("\nORB           0.006"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("\nORB mono      0.007"), std::string::npos) << run.out;
  const nlohmann::json j = nlohmann::json::parse(testing::Slurp(Path("l.json")));
  EXPECT_EQ(j[0]["estimate"]["label"], "ORB");
  EXPECT_EQ(j[1]["estimate"]["label"], "ORB mono");
  EXPECT_EQ(j[1]["estimate"]["path"], evo + "fr2_desk_ORB_kf_mono.txt");
  const testing::RunResult plain = Cheval(fmt::format("ape {} --json {}", files, Path("p.json")));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("\nfr2_desk_ORB_kf_mono.txt  "), std::string::npos) << plain.out;
  const std::string table = plain.out.substr(plain.out.find("2 estimates"));
  EXPECT_EQ(table.find(evo), std::string::npos) << "no folder in the table:\n" << table;
  EXPECT_FALSE(nlohmann::json::parse(testing::Slurp(Path("p.json")))[0]["estimate"].contains("label"));
  const testing::RunResult wrong = Cheval(fmt::format("ape {} --label only-one", files));
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_NE(wrong.err.find("--label given 1 times for 2 estimates"), std::string::npos) << wrong.err;
}

}  // namespace
}  // namespace cheval

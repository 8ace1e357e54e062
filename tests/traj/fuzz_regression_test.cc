// Replays the inputs of tests/data/fuzz/<target>/ (crashes and interesting inputs found by the
// libFuzzer targets of fuzz/, docs/fuzzing.md) through the very checks the fuzz targets run
// (fuzz/fuzz_checks.h): each input either parses into a trajectory with the target's properties, or
// the reader throws a cheval::InputError (UsageError for --columns) whose message begins with the path.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "../../fuzz/fuzz_checks.h"
#include "../support/test_data.h"

namespace cheval::traj {
namespace {

namespace fs = std::filesystem;

// The fuzz targets (fuzz/CMakeLists.txt), one folder of inputs each.
std::vector<std::string> Targets() {
  std::vector<std::string> targets(cheval::fuzz::kTrajectoryTargets.begin(), cheval::fuzz::kTrajectoryTargets.end());
  targets.push_back("stamp");
  targets.push_back("model");
  targets.push_back("curve");
  return targets;
}

struct FuzzInput {
  std::string target;
  std::string file;  // path of the input
};

// gtest prints the parameter of a failing case; the file says it all.
void PrintTo(const FuzzInput& input, std::ostream* os) { *os << input.file; }

std::vector<FuzzInput> ListInputs() {
  std::vector<FuzzInput> inputs;
  for (const std::string& target : Targets()) {
    const fs::path folder = fs::path(cheval::testing::FixturePath("fuzz")) / target;
    if (!fs::is_directory(folder)) continue;
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.is_regular_file()) files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
    for (const std::string& file : files) inputs.push_back({target, file});
  }
  return inputs;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << "cannot open " << path;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

class FuzzRegressionTest : public ::testing::TestWithParam<FuzzInput> {};

TEST_P(FuzzRegressionTest, ParsesWithPropertiesOrThrowsInputError) {
  const FuzzInput& input = GetParam();
  const std::string bytes = ReadBytes(input.file);
  // Any exception that is not a cheval::Error escapes and fails the test, as it crashes the target.
  const std::optional<std::string> violation =
      input.target == "stamp"   ? cheval::fuzz::CheckStampInput(bytes)
      : input.target == "model" ? cheval::fuzz::CheckModelInput(bytes)
      : input.target == "curve" ? cheval::fuzz::CheckCurveInput(bytes)
                                : cheval::fuzz::CheckTrajectoryInput(input.target, bytes);
  EXPECT_EQ(violation, std::nullopt) << input.file;
}

std::string TestName(const ::testing::TestParamInfo<FuzzInput>& info) {
  std::string name = info.param.target + "_" + fs::path(info.param.file).filename().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Inputs, FuzzRegressionTest, ::testing::ValuesIn(ListInputs()), TestName);

// An empty or missing folder would make the suite above pass vacuously.
TEST(FuzzRegression, EveryTargetHasInputs) {
  for (const std::string& target : Targets()) {
    const fs::path folder = fs::path(cheval::testing::FixturePath("fuzz")) / target;
    ASSERT_TRUE(fs::is_directory(folder)) << folder;
    EXPECT_FALSE(fs::is_empty(folder)) << folder;
  }
}

// The crashes the fuzzers found, with the message the fix gives them.
TEST(FuzzRegression, FoundCrashesThrowTheExactMessage) {
  struct Found {
    const char* target;
    const char* file;
    const char* message;
  };
  const Found kFound[] = {
      // A shear with determinant 1 passed the determinant check; its quaternion came out as zero.
      {"kitti", "shear_with_determinant_one",
       "fuzz.txt:2:1: error: expected a rotation matrix in fields 1-3, 5-7, 9-11 (r00..r22), got one that is not "
       "orthonormal (max |R*R^T - I| = inf)"},
      // qx = 1e175: q·q overflowed and the rotation silently became the identity.
      {"vins", "quaternion_norm_overflow",
       "fuzz.csv:1:32: error: quaternion (qw qx qy qz) is too large: its squared norm overflows a double; expected a "
       "rotation"},
  };
  for (const Found& found : kFound) {
    const std::string content = ReadBytes(cheval::testing::FixturePath(std::string("fuzz/") + found.target + "/" +
                                                                       found.file));
    ReadOptions options;
    options.format = *FormatFromString(found.target);
    try {
      ParseTrajectory(content, found.target == std::string("kitti") ? "fuzz.txt" : "fuzz.csv", options);
      ADD_FAILURE() << "no error for " << found.file;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), found.message);
    }
  }
}

}  // namespace
}  // namespace cheval::traj

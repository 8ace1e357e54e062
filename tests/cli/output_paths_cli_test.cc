// Outputs never destroy inputs or each other, and special files stay what they are (docs/output.md):
// every command checks its outputs against its inputs and each other before any work (exit 1, nothing
// written), `-` is standard output, and a device is written in place.
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "cli_runner.h"

namespace cheval::testing {
namespace {

namespace fs = std::filesystem;

class OutputPathsCliTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    const RunResult sim = Cheval("sim motion --kind car --duration 5 --rate 50 --noise 0.001 -o " + Path("ref.txt") +
                                 " --estimate " + Path("est.txt") + " --quiet");
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
    reference_ = Slurp(Path("ref.txt"));
    estimate_ = Slurp(Path("est.txt"));
  }

  // The command is refused with exit 1 before any work: the message names both paths, the inputs are
  // unchanged and no other file (nor a temporary) appeared in the folder (besides the runner's stdout
  // and stderr and the test's own symlink `link`).
  void ExpectRefused(const std::string& args, const std::string& first, const std::string& second) {
    SCOPED_TRACE(args);
    const RunResult run = Cheval(args);
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find(first), std::string::npos) << run.err;
    EXPECT_NE(run.err.find(second), std::string::npos) << run.err;
    EXPECT_EQ(Slurp(Path("ref.txt")), reference_);
    EXPECT_EQ(Slurp(Path("est.txt")), estimate_);
    int files = 0;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      files += name != "stdout" && name != "stderr" && name != "link";
    }
    EXPECT_EQ(files, 2) << "a file was written";
  }

  std::string reference_, estimate_;
};

TEST_F(OutputPathsCliTest, AnOutputThatIsAnInputIsRefused) {
  const std::string ref = Path("ref.txt"), est = Path("est.txt");
  ExpectRefused("convert " + ref + " -o " + ref, "-o " + ref, "input " + ref);
  ExpectRefused("velocity " + ref + " -o " + Path("v.txt") + " --json " + ref, "--json " + ref, "input " + ref);
  ExpectRefused("ape " + ref + " " + est + " --json " + ref, "--json " + ref, "input " + ref);
  ExpectRefused("ape " + ref + " " + est + " --errors " + est, "--errors " + est, "input " + est);
  ExpectRefused("compress " + ref + " -o " + ref, "-o " + ref, "input " + ref);
  ExpectRefused("report " + ref + " " + est + " -o " + ref, "-o " + ref, "input " + ref);
  ExpectRefused("info " + ref + " --json " + ref, "--json " + ref, "input " + ref);
  // The same file by another name: a relative path through a symlinked folder.
  fs::create_directory_symlink(dir_, Path("link"));
  ExpectRefused("rpe " + ref + " " + est + " --json " + Path("link") + "/est.txt", "--json", "input " + est);
  fs::remove(Path("link"));
}

TEST_F(OutputPathsCliTest, TwoOutputsOnOneFileAreRefused) {
  const std::string ref = Path("ref.txt"), est = Path("est.txt"), z = Path("z");
  ExpectRefused("ape " + ref + " " + est + " --json " + z + " --errors " + z, "--json " + z, "--errors " + z);
  ExpectRefused("velocity " + ref + " -o " + z + " --json " + z, "-o " + z, "--json " + z);
  ExpectRefused("convert " + ref + " -o " + z + " --to kitti --times-output " + z, "-o " + z, "--times-output " + z);
  ExpectRefused("sim motion --kind car --duration 1 -o " + z + " --estimate " + z, "-o " + z, "--estimate " + z);
}

TEST_F(OutputPathsCliTest, DashIsStandardOutputAndDevicesStayDevices) {
  const std::string ref = Path("ref.txt"), est = Path("est.txt");
  const RunResult run = Cheval("ape " + ref + " " + est + " --json - --quiet");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("\"rmse\""), std::string::npos) << run.out;
  EXPECT_FALSE(fs::exists("-"));
  EXPECT_FALSE(fs::exists(Path("-")));
  struct stat before {};
  ASSERT_EQ(::stat("/dev/null", &before), 0);
  ASSERT_TRUE(S_ISCHR(before.st_mode));
  EXPECT_EQ(Cheval("convert " + ref + " -o /dev/null --quiet").exit_code, 0);
  struct stat after {};
  ASSERT_EQ(::stat("/dev/null", &after), 0);
  EXPECT_TRUE(S_ISCHR(after.st_mode)) << "/dev/null was replaced";
  EXPECT_EQ(after.st_rdev, before.st_rdev);
}

TEST_F(OutputPathsCliTest, TheVehicleFileMayNotLiveInTheFolderThatIsReplaced) {
  const fs::path folder = Path("flight");
  ASSERT_EQ(Cheval("sim quadrotor --scenario hover --duration 1 -o " + folder.string() + " --quiet").exit_code, 0);
  const std::string vehicle = Slurp(folder / "vehicle.json");
  const RunResult run = Cheval("sim quadrotor --scenario hover --duration 1 --vehicle " + (folder / "vehicle.json").string() +
                               " -o " + folder.string());
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_EQ(Slurp(folder / "vehicle.json"), vehicle);
  // The estimator's outputs may not overwrite the data folder's files either.
  const RunResult estimate =
      Cheval("estimate quadrotor --data " + folder.string() + " --json " + (folder / "truth.csv").string());
  EXPECT_EQ(estimate.exit_code, 1) << estimate.err;
  EXPECT_NE(estimate.err.find("truth.csv"), std::string::npos) << estimate.err;
}

}  // namespace
}  // namespace cheval::testing

// Issue 13 through the executable: no option value ends in exit 70 or silently means something else,
// a run that would need more memory than the limit (docs/cli.md, "Memory limit") is refused before
// it allocates, non-finite results are exit 3, a failed write to standard output is exit 4, and a
// replaced output keeps its mode.
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_runner.h"

namespace cheval::testing {
namespace {

namespace fs = std::filesystem;

class LimitsCliTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    const RunResult sim = Cheval("sim motion --kind car --duration 20 --rate 50 --noise 0.001 -o " + Path("ref.txt") +
                                 " --truth " + Path("truth.txt") + " --estimate " + Path("est.txt") + " --quiet");
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }

  // `cheval ARGS` must fail with `code`, its message naming `flag` (and holding `text`), without an
  // internal error and without an output `out`.
  void ExpectFails(const std::string& args, int code, const std::string& flag, const std::string& text = "") {
    ExpectFailed(args, Cheval(args), code, flag, text);
  }
  // The same for a shell command line (an environment variable before the executable).
  void ExpectShellFails(const std::string& line, int code, const std::string& flag) {
    ExpectFailed(line, Shell(line), code, flag, "");
  }
  void ExpectFailed(const std::string& args, const RunResult& run, int code, const std::string& flag,
                    const std::string& text) {
    SCOPED_TRACE(args);
    EXPECT_EQ(run.exit_code, code) << run.err;
    EXPECT_NE(run.err.find(flag), std::string::npos) << run.err;
    if (!text.empty()) {
      EXPECT_NE(run.err.find(text), std::string::npos) << run.err;
    }
    EXPECT_EQ(run.err.find("internal error"), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(Path("out"))) << "an output was written";
  }

  std::string Eval(const std::string& command) const {
    return command + " " + Path("truth.txt") + " " + Path("est.txt") + " ";
  }
};

// CLI11 converted "-1" for an unsigned option by wrapping it (--max-points -1 = 2^64 - 1, 16.8 GB and
// exit 70; --seed -1 = 18446744073709551615), saturated "99999999999999999999", read "010" as octal,
// and took nan / inf / 1e400 for a double. Every numeric option is now checked as text first.
TEST_F(LimitsCliTest, NumericOptionsAreNeverWrappedSaturatedOrNonFinite) {
  const std::string out = " -o " + Path("out");
  ExpectFails(Eval("report") + out + " --max-points -1", 1, "--max-points: must be a whole number >= 0, got -1");
  ExpectFails(Eval("report") + out + " --max-points 99999999999999999999", 1,
              "--max-points: must be a whole number from 0 to 18446744073709551615");
  ExpectFails("sim motion --seed -1" + out, 1, "--seed: must be a whole number >= 0, got -1");
  ExpectFails("sim quadrotor --scenario hover --duration 1 --seed -1" + out, 1, "--seed");
  ExpectFails(Eval("ape") + "--align se3 --n-align 99999999999999999999 --json " + Path("out"), 1, "--n-align");
  ExpectFails(Eval("ape") + "--align se3 --n-align 5x --json " + Path("out"), 1, "--n-align: must be a whole number");
  ExpectFails(Eval("ape") + "--t-offset 1e400 --json " + Path("out"), 1, "--t-offset: must be a number within the range");
  ExpectFails("velocity " + Path("truth.txt") + out + " --window nan", 1, "--window: must be a finite number, got nan");
  ExpectFails("velocity " + Path("truth.txt") + out + " --window inf", 1, "--window");
  ExpectFails("velocity " + Path("truth.txt") + out + " --method savgol --window -inf", 1, "--window");
  ExpectFails("sim motion --noise inf" + out, 1, "--noise");
  ExpectFails("sim motion --estimate-drift nan --estimate " + Path("e2") + out, 1, "--estimate-drift");
  ExpectFails("estimate thrust --data " + Path("truth.txt") + " --rotor-delay nan", 1, "--rotor-delay");
  ExpectFails("compress " + Path("truth.txt") + out + " --tolerance 1e999", 1, "--tolerance");
  // Leading zeros are decimal: --n-align 010 aligns on 10 pairs, not 8.
  const RunResult run = Cheval(Eval("ape") + "--align se3 --n-align 010 --json - --quiet");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("\"pairs_used\": 10"), std::string::npos) << run.out;
}

// Values the library reads as "not given" were silently ignored when given.
TEST_F(LimitsCliTest, ZeroAndEmptyValuesAreRefusedNotIgnored) {
  for (const std::string command : {"ape", "rpe", "ase"}) {
    ExpectFails(Eval(command) + "--align se3 --n-align 0 --json " + Path("out"), 1,
                "--n-align must be at least 1 (leave it out to align on all pairs), got 0");
  }
  ExpectFails("velocity " + Path("truth.txt") + " -o " + Path("out") + " --window 0", 1,
              "--window must be a positive number of seconds, got 0");
  ExpectFails("velocity " + Path("truth.txt") + " -o " + Path("out") + " --method savgol --window 0", 1, "--window");
  ExpectFails("velocity " + Path("truth.txt") + " -o " + Path("out") + " --threads -1", 1,
              "--threads must be in 0..256 (0: every core), got -1");
  ExpectFails("convert " + Path("truth.txt") + " -o " + Path("out") + " --columns ''", 1,
              "--columns: must name the columns");
  ExpectFails(Eval("ape") + "--est-columns '' --json " + Path("out"), 1, "--est-columns: must name the columns");
  ExpectFails("info " + Path("truth.txt") + " --columns '' --json " + Path("out"), 1, "--columns");
}

// `sample --rate` within the 1e8-stamp cap needed ~18 GB; `sim motion --rate` 1e6 over 10 s ended in
// std::bad_alloc. The cost is computed first and compared with the limit (CHEVAL_MEMORY_LIMIT here,
// so the test does not depend on the machine). `report --max-points`: tests/report/report_cli_test.cc.
TEST_F(LimitsCliTest, OptionsThatCostMoreThanTheMemoryLimitAreRefusedBeforeAllocating) {
  ASSERT_EQ(Cheval("compress " + Path("truth.txt") + " -o " + Path("model.json") + " --quiet").exit_code, 0);
  const std::string limit = std::string("CHEVAL_MEMORY_LIMIT=64M ") + CHEVAL_EXE;
  ExpectShellFails(limit + " sample " + Path("model.json") + " --rate 5e6 -o " + Path("out"), 1,
                   "--rate would need about 20 GB of memory (1e+08 stamps over the model's 20.000 s); the limit is "
                   "67.1 MB (CHEVAL_MEMORY_LIMIT=64M)");
  ExpectShellFails(limit + " sim motion --duration 10 --rate 1e6 -o " + Path("out"), 1,
                   "--rate would need about 3.5 GB of memory (1e+07 samples over 10 s)");
  ExpectShellFails(
      limit + " sim motion --duration 100 --estimate-rate 1e5 --estimate " + Path("e2") + " -o " + Path("out"), 1,
      "--estimate-rate would need about");
  // Within the limit they run.
  const RunResult run = Shell(limit + " sample " + Path("model.json") + " --rate 1000 -o " + Path("s.txt"));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  // A limit that is not a byte count is a usage error.
  ExpectShellFails(std::string("CHEVAL_MEMORY_LIMIT=lots ") + CHEVAL_EXE + " sample " + Path("model.json") +
                       " --rate 10 -o " + Path("out"),
                   1, "CHEVAL_MEMORY_LIMIT must be a positive number of bytes");
}

// 1e300 coordinates gave inf errors, `std -nan`, JSON nulls and exit 0.
TEST_F(LimitsCliTest, NonFiniteResultsAreExitThreeWithTheReason) {
  {
    std::ofstream huge(Path("huge.txt"));
    for (int i = 0; i < 20; ++i) huge << 1.0 + 0.1 * i << " " << 1e300 * (1 + i) << " 0 0 0 0 0 1\n";
    std::ofstream small(Path("small.txt"));
    for (int i = 0; i < 20; ++i) small << 1.0 + 0.1 * i << " " << i << " 0 0 0 0 0 1\n";
  }
  for (const std::string command : {"ape", "rpe"}) {
    ExpectFails(command + " " + Path("huge.txt") + " " + Path("small.txt") + " --json " + Path("out"), 3,
                "is inf, not a finite number: the coordinates are too large to compute with");
  }
  // info's path length and compress's model: null and exit 70 before.
  {
    std::ofstream vast(Path("vast.txt"));
    for (int i = 0; i < 20; ++i) vast << 1.0 + 0.1 * i << " " << (i % 2 ? 1.7e308 : -1.7e308) << " 0 0 0 0 0 1\n";
  }
  ExpectFails("info " + Path("vast.txt") + " --json " + Path("out"), 3, "the path length is not a finite number");
  ExpectFails("compress " + Path("huge.txt") + " -o " + Path("model.json"), 3, "not finite");
}

// Results written to a full standard output were lost with exit 0 (a short output) or exit 70 (a long
// one, fmt's exception); --json - already failed with exit 4.
TEST_F(LimitsCliTest, AFailedWriteToStandardOutputIsExitFour) {
  for (const std::string& args :
       {Eval("ape"), Eval("ape") + "--json -", Eval("rpe") + "--errors -",
        "info " + Path("truth.txt") + " " + Path("est.txt") + " " + Path("ref.txt") + " " + Path("truth.txt") + " " +
            Path("est.txt") + " " + Path("ref.txt") + " " + Path("truth.txt") + " " + Path("est.txt"),
        "convert " + Path("truth.txt") + " -o -"}) {
    SCOPED_TRACE(args);
    const RunResult run = Shell("( " + std::string(CHEVAL_EXE) + " " + args + " >/dev/full )");
    EXPECT_EQ(run.exit_code, 4) << run.err;
    EXPECT_NE(run.err.find("<stdout>: error: cannot write: No space left on device"), std::string::npos) << run.err;
  }
}

// A closed pipe with SIGPIPE ignored (as a Python parent leaves it) gives EPIPE: exit 4 as well.
TEST_F(LimitsCliTest, AClosedPipeWithSigpipeIgnoredIsExitFour) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ::close(fds[0]);  // nobody reads
  const std::string err_path = Path("stderr.txt");
  const std::string truth = Path("truth.txt"), est = Path("est.txt");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::signal(SIGPIPE, SIG_IGN);  // kept across exec
    ::dup2(fds[1], STDOUT_FILENO);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(err, STDERR_FILENO);
    ::execl(CHEVAL_EXE, CHEVAL_EXE, "ape", truth.c_str(), est.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "ended by a signal";
  EXPECT_EQ(WEXITSTATUS(status), 4);
  EXPECT_NE(Slurp(err_path).find("<stdout>: error: cannot write: Broken pipe"), std::string::npos) << Slurp(err_path);
}

// A 0600 output became 0644 when replaced (issue 13); the output layer keeps the mode (common_test has
// the layer's own test); here through every kind of command output.
TEST_F(LimitsCliTest, AReplacedOutputKeepsItsMode) {
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"secret.json", Eval("ape") + "--json " + Path("secret.json")},
      {"secret.csv", Eval("ape") + "--errors " + Path("secret.csv")},
      {"secret.txt", "convert " + Path("truth.txt") + " -o " + Path("secret.txt")},
  };
  for (const auto& [name, args] : runs) {
    SCOPED_TRACE(args);
    std::ofstream(Path(name)) << "old\n";
    ASSERT_EQ(::chmod(Path(name).c_str(), 0600), 0);
    const RunResult run = Cheval(args + " --quiet");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    struct stat after {};
    ASSERT_EQ(::stat(Path(name).c_str(), &after), 0);
    EXPECT_EQ(after.st_mode & 07777, 0600u);
    EXPECT_NE(Slurp(Path(name)), "old\n");
  }
}

}  // namespace
}  // namespace cheval::testing

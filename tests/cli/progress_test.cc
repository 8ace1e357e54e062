// The terminal progress display of the CLI (tools/cheval/progress.h): what it draws, that it draws
// nothing when disabled, that it erases itself when a stage ends, and that the `cheval` executable
// shows it on a terminal only (a pseudo-terminal from `script`, util-linux) and never with --quiet.
#include "progress.h"

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "cli_runner.h"

namespace cheval::cli {
namespace {

// Everything written to a FILE* so far.
std::string Contents(std::FILE* f) {
  std::fflush(f);
  const long size = std::ftell(f);
  std::string text(static_cast<size_t>(size), '\0');
  std::rewind(f);
  EXPECT_EQ(std::fread(text.data(), 1, text.size(), f), text.size());
  std::fseek(f, 0, SEEK_END);
  return text;
}

TEST(TerminalProgress, DrawsABarAndErasesItAtTheEnd) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    TerminalProgress progress(f, /*enabled=*/true, std::chrono::milliseconds(0));
    ProgressFn fn = progress.Fn();
    ASSERT_TRUE(fn);
    fn("fitting windows", 3, 12);
    EXPECT_EQ(Contents(f), "\rfitting windows [######                  ]  25% (3/12)\x1b[K");
    fn("fitting windows", 12, 12);  // the end of the stage erases the line
    EXPECT_EQ(Contents(f), "\rfitting windows [######                  ]  25% (3/12)\x1b[K\r\x1b[K");
    fn("solver iterations", 4, 0);  // unknown total: a count
  }
  const std::string all = Contents(f);
  EXPECT_NE(all.find("\rsolver iterations (4)\x1b[K"), std::string::npos) << all;
  EXPECT_EQ(all.substr(all.size() - 4), "\r\x1b[K");  // the destructor erased it
  std::fclose(f);
}

TEST(TerminalProgress, ThrottlesRedrawsWithinAStage) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  TerminalProgress progress(f, /*enabled=*/true, std::chrono::hours(1));
  for (int i = 0; i < 100; ++i) progress.Update("reading", i, 1000);
  const std::string once = Contents(f);
  EXPECT_EQ(once, "\rreading [                        ]   0% (0/1000)\x1b[K");
  progress.Update("writing", 1, 10);  // a new stage is drawn at once
  EXPECT_NE(Contents(f).find("writing"), std::string::npos);
  progress.Clear();
  std::fclose(f);
}

TEST(TerminalProgress, DisabledDrawsNothingAndGivesNoCallback) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    TerminalProgress progress(f, /*enabled=*/false, std::chrono::milliseconds(0));
    EXPECT_FALSE(progress.Fn());
    progress.Update("fitting windows", 1, 2);
    progress.Clear();
  }
  EXPECT_EQ(Contents(f), "");
  std::fclose(f);
}

using cheval::testing::CliTest;
using cheval::testing::RunResult;

// True when util-linux's `script` can give the command a pseudo-terminal here.
bool HaveScript() { return std::system("script -qec true /dev/null >/dev/null 2>&1") == 0; }

TEST_F(CliTest, ProgressOnlyOnATerminalAndNeverWithQuiet) {
  RunResult sim = Cheval("sim motion --kind drone --seed 2 --noise 0.0005 --duration 200 --rate 200 -o " + Path("m.txt"));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  // stderr is a file here: no progress, no escape sequences.
  RunResult plain = Cheval("velocity " + Path("m.txt") + " -o " + Path("v.txt"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.err.find('\r'), std::string::npos) << plain.err;
  RunResult quiet_sim = Cheval("sim motion --kind car --seed 1 -o " + Path("c.txt") + " --quiet");
  ASSERT_EQ(quiet_sim.exit_code, 0) << quiet_sim.err;
  EXPECT_EQ(quiet_sim.err, "");  // the "wrote ..." line is informational
  if (!HaveScript()) GTEST_SKIP() << "util-linux `script` is not available to make a pseudo-terminal";
  // On a terminal (stdout and stderr both go to the pty; `script` copies them to its stdout).
  const std::string command = std::string(CHEVAL_EXE) + " velocity " + Path("m.txt") + " -o " + Path("v2.txt");
  RunResult tty = Shell("script -qec '" + command + "' /dev/null");
  ASSERT_EQ(tty.exit_code, 0) << tty.err;
  EXPECT_NE(tty.out.find("fitting"), std::string::npos) << tty.out;
  EXPECT_NE(tty.out.find("\r\x1b[K"), std::string::npos) << "the bar is erased at the end";
  // The estimator counts its solver iterations.
  RunResult estimate = Shell("script -qec '" + std::string(CHEVAL_EXE) +
                             " estimate quadrotor --scenario hover --duration 2' /dev/null");
  ASSERT_EQ(estimate.exit_code, 0) << estimate.err;
  EXPECT_NE(estimate.out.find("\rsolver iterations (1)"), std::string::npos) << estimate.out;
  RunResult tty_quiet = Shell("script -qec '" + command + " --quiet' /dev/null");
  ASSERT_EQ(tty_quiet.exit_code, 0) << tty_quiet.err;
  std::string without_line_ends = tty_quiet.out;  // a pty turns "\n" into "\r\n"
  for (size_t at; (at = without_line_ends.find("\r\n")) != std::string::npos;) without_line_ends.erase(at, 1);
  EXPECT_EQ(without_line_ends.find('\r'), std::string::npos) << "no progress with --quiet: " << tty_quiet.out;
}

}  // namespace
}  // namespace cheval::cli

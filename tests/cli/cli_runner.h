#pragma once
// Running the `cheval` executable (CHEVAL_EXE) from a test as a process: exit code, stdout and
// stderr, in a fresh temporary folder per test that is removed afterwards.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "../support/test_data.h"

namespace cheval::testing {

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = FreshTestDir("cheval_cli_");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Runs `cheval ARGS` through the shell with stdout and stderr captured in files.
  RunResult Cheval(const std::string& args) const { return Shell(std::string(CHEVAL_EXE) + " " + args); }

  // Runs a shell command line with stdout and stderr captured in files.
  RunResult Shell(const std::string& command_line) const {
    const std::filesystem::path out = dir_ / "stdout", err = dir_ / "stderr";
    const std::string command = command_line + " >" + out.string() + " 2>" + err.string();
    const int status = std::system(command.c_str());
    RunResult run;
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.out = Slurp(out);
    run.err = Slurp(err);
    return run;
  }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  std::filesystem::path dir_;
};

}  // namespace cheval::testing

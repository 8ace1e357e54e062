#pragma once
// Where tests find data: the project's own fixtures (tests/data) and the shared real data
// (../shared/data, or $CHEVAL_DATA_DIR). Shared data missing is a skip on a developer machine
// and a failure in CI (CI=true), so CI can never pass without exercising it.

#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

namespace cheval::testing {

inline std::string FixturePath(const std::string& relative) { return std::string(CHEVAL_TEST_DATA_DIR) + "/" + relative; }

inline std::string SharedDataDir() {
  const char* env = std::getenv("CHEVAL_DATA_DIR");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string(CHEVAL_DATA_DIR);
}

/// An empty folder of the running test's own: temp/PREFIX<test name>_<pid>, whatever an earlier run
/// left there removed first. The caller removes it when done.
inline std::filesystem::path FreshTestDir(const std::string& prefix) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      (prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline bool InCi() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace cheval::testing

/// Skips the test when the shared data folder is absent, except in CI where that is a failure.
#define CHEVAL_REQUIRE_SHARED_DATA()                                                                       \
  do {                                                                                                     \
    if (!std::filesystem::is_directory(::cheval::testing::SharedDataDir())) {                             \
      if (::cheval::testing::InCi()) FAIL() << "shared data missing in CI: " << ::cheval::testing::SharedDataDir(); \
      GTEST_SKIP() << "shared data not found at " << ::cheval::testing::SharedDataDir();                   \
    }                                                                                                      \
  } while (0)

// Replays tests/data/fuzz/bag_<container>/ (seeds written by bag::WriteBag, inputs the recording fuzz
// targets found) through the checks the targets run (fuzz/bag_fuzzer_checks.h).
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "../../fuzz/bag_fuzzer_checks.h"
#include "../support/test_data.h"

namespace cheval::fuzz {
namespace {

namespace fs = std::filesystem;

TEST(BagFuzzRegression, EveryKeptInputPassesTheTargetsChecks) {
  int inputs = 0;
  for (const std::string_view target : kBagTargets) {
    const fs::path folder = fs::path(cheval::testing::FixturePath("fuzz")) / ("bag_" + std::string(target));
    ASSERT_TRUE(fs::is_directory(folder)) << folder;
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
      std::ifstream in(entry.path(), std::ios::binary);
      const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      EXPECT_EQ(CheckBagInput(target, data), std::nullopt) << entry.path();
      ++inputs;
    }
  }
  EXPECT_GE(inputs, 9);
}

}  // namespace
}  // namespace cheval::fuzz

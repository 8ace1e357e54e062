// The memory limit of a run (include/cheval/common/memory.h, docs/cli.md "Memory limit"): the byte
// counts CHEVAL_MEMORY_LIMIT takes, the default derived from the machine, and CheckMemory's two
// errors naming the option and the cost.
#include "cheval/common/memory.h"

#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "cheval/common/error.h"

namespace cheval {
namespace {

// Sets CHEVAL_MEMORY_LIMIT for one scope and restores what was there.
class ScopedLimit {
 public:
  explicit ScopedLimit(const char* value) {
    if (const char* old = std::getenv(kName)) old_ = old;
    if (value) ::setenv(kName, value, 1);
    else ::unsetenv(kName);
  }
  ~ScopedLimit() {
    if (old_) ::setenv(kName, old_->c_str(), 1);
    else ::unsetenv(kName);
  }

 private:
  static constexpr const char* kName = "CHEVAL_MEMORY_LIMIT";
  std::optional<std::string> old_;
};

TEST(MemoryTest, ParsesByteCountsWithBinarySuffixes) {
  EXPECT_EQ(ParseByteCount("4096"), 4096u);
  EXPECT_EQ(ParseByteCount("512K"), 512u << 10);
  EXPECT_EQ(ParseByteCount("3m"), 3u << 20);
  EXPECT_EQ(ParseByteCount("2G"), 2ull << 30);
  EXPECT_EQ(ParseByteCount("2GB"), 2ull << 30);
  EXPECT_EQ(ParseByteCount("2GiB"), 2ull << 30);
  EXPECT_EQ(ParseByteCount("1T"), 1ull << 40);
  EXPECT_EQ(ParseByteCount("100B"), 100u);
  for (const char* bad : {"", "0", "-1", "1.5G", "G", "1X", "1 G", "nan", "99999999999999999999", "16777216T"}) {
    EXPECT_EQ(ParseByteCount(bad), std::nullopt) << bad;
  }
}

TEST(MemoryTest, FormatsBytesForPeople) {
  EXPECT_EQ(FormatBytes(512), "512 B");
  EXPECT_EQ(FormatBytes(1500), "1.5 kB");
  EXPECT_EQ(FormatBytes(18.6e9), "18.6 GB");
  EXPECT_EQ(FormatBytes(4e20), "400 EB");
}

TEST(MemoryTest, TheDefaultLimitIsHalfTheAvailableMemory) {
  const ScopedLimit unset(nullptr);
  EXPECT_GT(AvailableMemory(), 0u);
  EXPECT_EQ(MemoryLimit(), AvailableMemory() / 2);
  const ScopedLimit set("1G");
  EXPECT_EQ(MemoryLimit(), 1ull << 30);
  const ScopedLimit bad("lots");
  try {
    MemoryLimit();
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("CHEVAL_MEMORY_LIMIT must be a positive number of bytes"), std::string::npos);
  }
}

TEST(MemoryTest, CheckMemoryNamesTheOptionAndTheCost) {
  const ScopedLimit limit("1M");
  EXPECT_NO_THROW(CheckMemory({"ModelGridStamps", "rate_hz", 1048576.0, "5000 stamps", MemoryCost::kOption}));
  try {
    CheckMemory({"ModelGridStamps", "rate_hz", 2e9, "1e+07 stamps", MemoryCost::kOption});
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.options(), "ModelGridStamps");
    EXPECT_EQ(e.field(), "rate_hz");
    EXPECT_EQ(e.rule(), "would need about 2 GB of memory (1e+07 stamps); the limit is 1.05 MB (CHEVAL_MEMORY_LIMIT=1M)");
  }
  try {
    CheckMemory({"ReportOptions", "max_points", 5e6, "80000 plotted values", MemoryCost::kData});
    FAIL() << "no error";
  } catch (const OptionError&) {
    FAIL() << "a cost that depends on the data is not a usage error";
  } catch (const ComputeError& e) {
    EXPECT_EQ(std::string(e.what()), "ReportOptions::max_points would need about 5 MB of memory (80000 plotted values); "
                                     "the limit is 1.05 MB (CHEVAL_MEMORY_LIMIT=1M)");
  }
  // A cost that is not a number is never below the limit.
  EXPECT_THROW(CheckMemory({"S", "f", std::nan(""), "?", MemoryCost::kOption}), OptionError);
}

}  // namespace
}  // namespace cheval

#include "cheval/traj/stamp.h"

#include <cstdint>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace cheval::traj {
namespace {

int64_t Seconds(std::string_view text) {
  const StampParseResult r = ParseDecimalStamp(text, 9);
  EXPECT_FALSE(r.error) << text;
  return r.value;
}

std::optional<StampParseError> SecondsError(std::string_view text) { return ParseDecimalStamp(text, 9).error; }

TEST(ParseDecimalStamp, EpochSecondsAreExact) {
  // A double holds 1403636579.758555651 only to ~2.4e-7 s; the digits must survive exactly.
  EXPECT_EQ(Seconds("1403636579.758555651"), 1403636579758555651LL);
  EXPECT_NE(static_cast<int64_t>(1403636579.758555651 * 1e9), 1403636579758555651LL);
  EXPECT_EQ(Seconds("1311868164.363181"), 1311868164363181000LL);
  EXPECT_EQ(Seconds("1.403715529112143517e+09"), 1403715529112143517LL);
  EXPECT_EQ(Seconds("1.403715529112143517E9"), 1403715529112143517LL);
  EXPECT_EQ(Seconds("0.000000e+00"), 0);
  EXPECT_EQ(Seconds("1.037359e-01"), 103735900);
  EXPECT_EQ(Seconds("4.705816e+02"), 470581600000LL);
  EXPECT_EQ(Seconds("-1.5"), -1500000000LL);
  EXPECT_EQ(Seconds("+2"), 2000000000LL);
  EXPECT_EQ(Seconds("7."), 7000000000LL);
  EXPECT_EQ(Seconds(".25"), 250000000LL);
  EXPECT_EQ(Seconds("000012.5"), 12500000000LL);
}

TEST(ParseDecimalStamp, RoundsHalfToEvenBeyondNanoseconds) {
  EXPECT_EQ(Seconds("1403715539.8121430874"), 1403715539812143087LL);  // rpg files carry 10 decimals
  EXPECT_EQ(Seconds("1403715539.8121430875"), 1403715539812143088LL);  // tie -> even
  EXPECT_EQ(Seconds("1403715539.8121430885"), 1403715539812143088LL);  // tie -> even
  EXPECT_EQ(Seconds("1403715539.81214308850001"), 1403715539812143089LL);  // above the tie
  EXPECT_EQ(Seconds("0.0000000005"), 0);
  EXPECT_EQ(Seconds("0.0000000015"), 2);
  EXPECT_EQ(Seconds("-0.0000000015"), -2);
  EXPECT_EQ(Seconds("3.6403065e-16"), 0);   // crazyflie's "zero"
  EXPECT_EQ(Seconds("-5.7841087e-16"), 0);
  EXPECT_EQ(Seconds("1e-400"), 0);          // far below 1 ns
  // 40 significant digits: the digits past the 36 kept still break the tie.
  EXPECT_EQ(Seconds("0.0000000025000000000000000000000000000001"), 3);
  EXPECT_EQ(Seconds("0.0000000025000000000000000000000000000000"), 2);
}

TEST(ParseDecimalStamp, Int64Limits) {
  EXPECT_EQ(Seconds("9223372036.854775807"), std::numeric_limits<int64_t>::max());
  EXPECT_EQ(Seconds("-9223372036.854775808"), std::numeric_limits<int64_t>::min());
  EXPECT_EQ(SecondsError("9223372036.854775808"), StampParseError::kOutOfRange);
  EXPECT_EQ(SecondsError("1e11"), StampParseError::kOutOfRange);
  EXPECT_EQ(SecondsError("123456789012345678901234567890"), StampParseError::kOutOfRange);
  EXPECT_EQ(SecondsError("1e99999999999"), StampParseError::kOutOfRange);
}

TEST(ParseDecimalStamp, RejectsWhatIsNotADecimal) {
  for (const char* text : {"", "-", "+", ".", "abc", "nan", "inf", "-inf", "0x10", "1.2.3", "1e", "1e+", "12a.5",
                           "1 ", " 1", "1,5", "--1", "+-1", "1e5x"}) {
    EXPECT_EQ(SecondsError(text), StampParseError::kNotANumber) << "'" << text << "'";
  }
}

TEST(ParseDecimalStamp, IntegerNanoseconds) {
  EXPECT_EQ(ParseDecimalStamp("1403715524907143168", 0, true).value, 1403715524907143168LL);
  EXPECT_EQ(ParseDecimalStamp("1.4e18", 0, true).value, 1400000000000000000LL);
  EXPECT_EQ(ParseDecimalStamp("1403715524912143168.5", 0, true).error, StampParseError::kNotAnInteger);
  EXPECT_EQ(ParseDecimalStamp("1e-3", 0, true).error, StampParseError::kNotAnInteger);
  // Without require_integer, scale 0 rounds.
  EXPECT_EQ(ParseDecimalStamp("2.5", 0).value, 2);
  EXPECT_EQ(ParseDecimalStamp("3.5", 0).value, 4);
}

TEST(FormatSeconds, PrintsNineDecimalsExactly) {
  EXPECT_EQ(FormatSeconds(1403715529112143517LL), "1403715529.112143517");
  EXPECT_EQ(FormatSeconds(0), "0.000000000");
  EXPECT_EQ(FormatSeconds(-5), "-0.000000005");
  EXPECT_EQ(FormatSeconds(-1500000000LL), "-1.500000000");
  EXPECT_EQ(FormatSeconds(std::numeric_limits<int64_t>::min()), "-9223372036.854775808");
  EXPECT_EQ(FormatSeconds(std::numeric_limits<int64_t>::max()), "9223372036.854775807");
}

TEST(FormatSeconds, RoundTripsThroughTheParser) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 10000; ++i) {
    const auto stamp = static_cast<int64_t>(rng());
    EXPECT_EQ(Seconds(FormatSeconds(stamp)), stamp);
  }
}

}  // namespace
}  // namespace cheval::traj

// What the readers refuse beyond a single field (stamps spanning more than int64 ns, "+-1", bytes
// that garble a message, unbounded input), and that arrays and the writers are held to the readers'
// rules (traj/validate.h).
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "cheval/traj/validate.h"
#include "../support/test_data.h"

namespace cheval::traj {
namespace {

// The message of the InputError that parsing `text` as `path` throws ("" when none is thrown).
std::string ParseError(const std::string& text, const ReadOptions& options = {}, const std::string& path = "t.txt") {
  try {
    ParseTrajectory(text, path, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string ReadError(const std::string& path, const ReadOptions& options = {}) {
  try {
    ReadTrajectory(path, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

class TempFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::FreshTestDir("cheval_validate_");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  std::filesystem::path dir_;
};

TEST(SignTest, TwoSignsAreNoNumber) {
  // from_chars read "+-1" as -1 after the '+' was dropped.
  EXPECT_EQ(ParseError("0 +-1 0 0 0 0 0 1\n"), "t.txt:1:3: error: expected a number for field 2 (x), got '+-1'");
  EXPECT_EQ(ParseError("0 -+1 0 0 0 0 0 1\n"), "t.txt:1:3: error: expected a number for field 2 (x), got '-+1'");
  EXPECT_EQ(ParseError("0 ++1 0 0 0 0 0 1\n"), "t.txt:1:3: error: expected a number for field 2 (x), got '++1'");
  EXPECT_EQ(ParseError("0 --1 0 0 0 0 0 1\n"), "t.txt:1:3: error: expected a number for field 2 (x), got '--1'");
  EXPECT_EQ(ParseError("0 0 0 0 0 0 0 +-1\n"), "t.txt:1:15: error: expected a number for field 8 (qw), got '+-1'");
  EXPECT_EQ(ParseError("+-1 0 0 0 0 0 0 1\n"),
            "t.txt:1:1: error: expected a time stamp in seconds for field 1 (t), got '+-1'");
  // One sign is still a number.
  EXPECT_EQ(ParseTrajectory("0 +1 -1 0 0 0 0 1\n", "t.txt").positions()(0, 0), 1.0);
}

TEST(QuoteFieldTest, EscapesWhatGarblesATerminalAndCutsLongFields) {
  EXPECT_EQ(QuoteField("abc"), "'abc'");
  EXPECT_EQ(QuoteField(std::string("\x1b[31mred\0\r\t\n", 12)), "'\\x1b[31mred\\0\\r\\t\\n'");
  EXPECT_EQ(QuoteField("\xEF\xBB\xBF" "1.0"), "'\\u{feff}1.0'");            // byte-order mark
  EXPECT_EQ(QuoteField("\xE2\x80\xAE" "abc"), "'\\u{202e}abc'");            // right-to-left override
  EXPECT_EQ(QuoteField("caf\xC3\xA9"), "'caf\xC3\xA9'");                    // printable UTF-8 kept
  EXPECT_EQ(QuoteField("\xFF\xC3"), "'\\xff\\xc3'");                        // not UTF-8
  EXPECT_EQ(QuoteField("a'b\\c"), "'a\\'b\\\\c'");
  EXPECT_EQ(QuoteField(std::string(10'000'000, '7')), "'" + std::string(kQuotedFieldLength, '7') + "'…");
}

TEST(QuoteFieldTest, EveryReaderMessageQuotesTheFieldEscaped) {
  // Raw bytes of the file reached the terminal before: an ESC sequence, a CR, a byte-order mark.
  EXPECT_EQ(ParseError("0 \x1b[2J 0 0 0 0 0 1\n"),
            "t.txt:1:3: error: expected a number for field 2 (x), got '\\x1b[2J'");
  EXPECT_EQ(ParseError("0 1\r2 0 0 0 0 0 1\n"), "t.txt:1:3: error: expected a number for field 2 (x), got '1\\r2'");
  EXPECT_EQ(ParseError("\xEF\xBB\xBF" "0 0 0 0 0 0 0 1\n"),
            "t.txt:1:1: error: expected a time stamp in seconds for field 1 (t), got '\\u{feff}0'");
  const std::string long_field(10'000, '9');
  EXPECT_EQ(ParseError("0 " + long_field + "x 0 0 0 0 0 1\n"),
            "t.txt:1:3: error: expected a number for field 2 (x), got '" + std::string(40, '9') + "'…");
  EXPECT_EQ(ParseError("0 0 0 nan\x1b 0 0 0 1\n"),
            "t.txt:1:7: error: expected a number for field 4 (z), got 'nan\\x1b'");
  EXPECT_EQ(ParseError("99999999999999999999\x07 0 0 0 0 0 0 1\n"),
            "t.txt:1:1: error: expected a time stamp in seconds for field 1 (t), got '99999999999999999999\\x07'");
  ReadOptions euroc;
  euroc.format = Format::kEuroc;
  EXPECT_EQ(ParseError("1.5\x1b,0,0,0,1,0,0,0\n", euroc, "t.csv"),
            "t.csv:1:1: error: expected a time stamp in nanoseconds for field 1 (t_ns), got '1.5\\x1b'");
}

TEST(StampSpanTest, ASpanBeyondInt64NanosecondsIsRefusedWithTheLine) {
  // Each stamp is valid alone (±5e9 s is within ±9.2e9 s), their difference is not.
  EXPECT_EQ(ParseError("-5000000000 0 0 0 0 0 0 1\n# comment\n5000000000 0 0 0 0 0 0 1\n"),
            "t.txt:3:1: error: time stamp 5000000000.000000000 s is 1e+10 s away from the stamp of line 1 "
            "(-5000000000.000000000 s); expected the stamps of one trajectory to span at most int64 nanoseconds "
            "(about 292 years, 9.2e9 s)");
  // Going down past the first stamp counts too, against the largest one so far.
  EXPECT_EQ(ParseError("0 0 0 0 0 0 0 1\n9000000000 0 0 0 0 0 0 1\n-1000000000 0 0 0 0 0 0 1\n"),
            "t.txt:3:1: error: time stamp -1000000000.000000000 s is 1e+10 s away from the stamp of line 2 "
            "(9000000000.000000000 s); expected the stamps of one trajectory to span at most int64 nanoseconds "
            "(about 292 years, 9.2e9 s)");
  ReadOptions euroc;
  euroc.format = Format::kEuroc;
  EXPECT_NE(ParseError("-9000000000000000000,0,0,0,1,0,0,0\n9000000000000000000,0,0,0,1,0,0,0\n", euroc, "t.csv")
                .find("t.csv:2:1: error: time stamp 9000000000.000000000 s is 1.8e+10 s away from the stamp of line 1"),
            std::string::npos);
  ReadOptions csv;
  csv.format = Format::kCsv;
  csv.columns = ColumnMap::Parse("px,py,pz,t");
  EXPECT_NE(ParseError("0,0,0,-5e9\n0,0,0,5e9\n", csv).find("t.txt:2:7: error: time stamp 5000000000.000000000 s"),
            std::string::npos);
  // The widest span that fits is read, and its duration is exact.
  const Trajectory widest = ParseTrajectory("-4611686018.427387904 0 0 0 0 0 0 1\n4611686018.427387903 0 0 0 0 0 0 1\n",
                                            "t.txt");
  EXPECT_EQ(widest.stamps_ns()[1] - widest.stamps_ns()[0], std::numeric_limits<int64_t>::max());
}

TEST_F(TempFolder, AKittiTimesFileSpanningMoreThanInt64IsRefused) {
  const std::string poses = Write("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n");
  const std::string times = Write("times.txt", "-5e9\n5e9\n");
  ReadOptions options;
  options.format = Format::kKitti;
  options.kitti_times_path = times;
  EXPECT_EQ(ReadError(poses, options).rfind(times + ":2:1: error: time stamp 5000000000.000000000 s is 1e+10 s", 0), 0u)
      << ReadError(poses, options);
}

TEST_F(TempFolder, ANulByteEndsTheReadAtItsLine) {
  const std::string path = Write("nul.txt", std::string("0 0 0 0 0 0 0 1\n1 0 0\0 0 0 0 0 1\n", 32));
  EXPECT_EQ(ReadError(path), path + ":2:6: error: contains a NUL byte (\\0); expected a text file");
}

TEST_F(TempFolder, ALineLongerThanTheLimitIsRefusedWithoutReadingOn) {
  const std::string path = Write("long.txt", "0 0 0 0 0 0 0 1\n" + std::string(kMaxInputLineBytes + 10, '1'));
  EXPECT_EQ(ReadError(path).rfind(path + ":2:1: error: no newline in the first ", 0), 0u) << ReadError(path);
  EXPECT_NE(ReadError(path).find(" of this line; expected lines of a trajectory file, at most 1048576 bytes "
                                 "(1 MiB) each"),
            std::string::npos)
      << ReadError(path);
}

TEST_F(TempFolder, DevZeroIsRefusedAtOnce) {
  // Read whole before: /dev/zero grew to 7.7 GB before anything was said.
  EXPECT_EQ(ReadError("/dev/zero"), "/dev/zero:1:1: error: contains a NUL byte (\\0); expected a text file");
}

// A file is read a block (1 MiB) at a time and only the lines not read yet are kept. Lines that
// straddle the blocks, a CRLF split between two blocks and a comment header longer than a block (the
// format is detected past it) read exactly as the same text parsed whole.
TEST_F(TempFolder, AFileReadInBlocksReadsAsTheSameTextInMemory) {
  constexpr size_t kBlock = size_t{1} << 20;
  std::string text = "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
  while (text.size() < kBlock + kBlock / 2) text += "# a comment line of the header, read before the format is known\n";
  for (int64_t i = 0; text.size() < 4 * kBlock; ++i) {
    // Lines of varying length: the block ends fall at every place of a line.
    text += fmt::format("{},{},{:.{}f},-3.25,1,0,0,0", 1'403'715'273'262'142'976 + i * 5'000'000, i * 1e-3, 0.5 + i,
                        static_cast<int>(i % 17));
    // A CR at the last byte of the third block, its LF at the first byte of the fourth (spaces pad
    // the line: still 8 fields).
    const size_t cr = 3 * kBlock - 1;
    if (text.size() <= cr && text.size() + 200 > cr) {
      text += std::string(cr - text.size(), ' ') + "\r\n";
    } else {
      text += "\n";
    }
  }
  ASSERT_EQ(text.substr(3 * kBlock - 1, 2), "\r\n");
  const std::string path = Write("blocks.csv", text);
  Format read_format = Format::kAuto, parsed_format = Format::kAuto;
  const Trajectory read = ReadTrajectory(path, {}, &read_format);
  const Trajectory parsed = ParseTrajectory(text, path, {}, &parsed_format);
  EXPECT_EQ(read_format, Format::kEuroc);
  EXPECT_EQ(parsed_format, Format::kEuroc);
  ASSERT_GT(read.size(), 40000);
  ASSERT_EQ(read.size(), parsed.size());
  EXPECT_TRUE(std::ranges::equal(read.stamps_ns(), parsed.stamps_ns()));
  EXPECT_EQ(read.positions(), parsed.positions());
  EXPECT_EQ(read.View().quaternions(), parsed.View().quaternions());
}

// Where a line is, and a column in a line that began in the block before, are counted across blocks.
TEST_F(TempFolder, ErrorsPastTheFirstBlockNameTheirLineAndColumn) {
  constexpr size_t kBlock = size_t{1} << 20;
  std::string text;
  int64_t lines = 0;
  for (; text.size() + 30 < kBlock; ++lines) text += fmt::format("{}.5 1 2 3 0 0 0 1\n", lines);
  // The line that straddles the first block's end has a bad field after the end.
  const std::string straddling = fmt::format("{}.5 1 2 3 0 0 0 1", lines) + std::string(40, ' ') + std::string(30, '1');
  ASSERT_GT(text.size() + straddling.size() - 30, kBlock);
  text += straddling + "\n";
  const std::string path = Write("bad.txt", text);
  ReadOptions tum;
  tum.format = Format::kTum;
  EXPECT_EQ(ReadError(path, tum),
            fmt::format("{}:{}:{}: error: expected 8 fields (t x y z qx qy qz qw), got 9", path, lines + 1,
                        straddling.size() - 29));
  // A NUL byte in the second block, in a line that began in the first.
  std::string nul = text.substr(0, text.size() - straddling.size() - 1) + straddling;
  nul[nul.size() - 3] = '\0';
  const std::string nul_path = Write("nul_later.txt", nul + "\n");
  EXPECT_EQ(ReadError(nul_path), fmt::format("{}:{}:{}: error: contains a NUL byte (\\0); expected a text file",
                                             nul_path, lines + 1, straddling.size() - 2));
}

TEST_F(TempFolder, AFileLargerThanTheLimitIsRefusedBeforeReading) {
  const std::string path = (dir_ / "huge.txt").string();
  std::ofstream(path) << "0 0 0 0 0 0 0 1\n";
  std::filesystem::resize_file(path, MaxInputFileBytes() + 1);  // sparse: no disk space used
  const std::string error = ReadError(path);
  EXPECT_EQ(error.rfind(path + ":0:0: error: the file is " + std::to_string(MaxInputFileBytes() + 1) + " bytes", 0), 0u)
      << error;
  EXPECT_NE(error.find("; the largest input file read is " + std::to_string(MaxInputFileBytes()) + " bytes"),
            std::string::npos)
      << error;
  EXPECT_LE(MaxInputFileBytes(), kMaxInputFileBytes);
}

TEST_F(TempFolder, ADirectoryAndAPathWithANulAreRefused) {
  EXPECT_EQ(ReadError(dir_.string()), dir_.string() + ":0:0: error: is a directory; expected a trajectory file");
  const std::string path = Write("a", "0 0 0 0 0 0 0 1\n");
  EXPECT_EQ(ReadError(path + std::string("\0b", 2)),
            "'" + path + "\\0b':0:0: error: the file name contains a NUL byte (\\0); expected a path");
}

TEST(ValidatePosesTest, ArraysAreHeldToTheReadersRules) {
  Trajectory t;
  const double q[4] = {0, 0, 0, 1}, zero[4] = {0, 0, 0, 0};
  const double p[3] = {1, 2, 3}, bad[3] = {1, std::nan(""), 3};
  t.Append(0, p, q);
  EXPECT_NO_THROW(ValidatePoses(t.View(), "<array>"));
  t.Append(1, bad, q);
  try {
    ValidatePoses(t.View(), "<array>");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "<array>:0:0: error: row 1: positions[1, 1] (y) is nan; expected a finite number");
  }
  Trajectory z;
  z.Append(0, p, zero);
  EXPECT_EQ(FindPoseProblem(z.View())->what, "quaternion (quaternions[0]) has zero norm; expected a rotation");
  Trajectory wide;
  wide.Append(-5'000'000'000'000'000'000, p, q);
  wide.Append(5'000'000'000'000'000'000, p, q);
  EXPECT_EQ(FindPoseProblem(wide.View())->row, 1);
  EXPECT_EQ(FindPoseProblem(wide.View())->what,
            "time stamp 5000000000.000000000 s is 1e+10 s away from the stamp of row 0 (-5000000000.000000000 s); "
            "expected the stamps of one trajectory to span at most int64 nanoseconds (about 292 years, 9.2e9 s)");
  Trajectory velocity(Channels{OrientationKind::kQuaternion, true, false, true});
  const double v[3] = {0, -std::numeric_limits<double>::infinity(), 0};
  velocity.Append(0, p, q, v);
  EXPECT_EQ(FindPoseProblem(velocity.View())->what, "velocities[0, 1] (y) is -inf; expected a finite number");
}

TEST(WriteTest, OnlyWhatReadsBackIsWritten) {
  Trajectory t;
  const double q[4] = {0, 0, 0, 1}, p[3] = {1, std::numeric_limits<double>::infinity(), 3};
  t.Append(0, p, q);
  try {
    FormatTrajectory(t.View(), Format::kTum);
    FAIL() << "no error";
  } catch (const ComputeError& e) {
    EXPECT_STREQ(e.what(),
                 "cannot write tum: row 0: positions[0, 1] (y) is inf; expected a finite number (the file would not read back)");
  }
  EXPECT_THROW(FormatTrajectory(Trajectory().View(), Format::kEuroc), ComputeError);
  const std::string path = (std::filesystem::temp_directory_path() / ("cheval_not_written_" + std::to_string(::getpid()))).string();
  EXPECT_THROW(WriteTrajectory(path, t.View(), Format::kTum), ComputeError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace cheval::traj

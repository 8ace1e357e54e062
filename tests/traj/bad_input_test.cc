// The broken files of tests/data/bad, each with the exact message of the library (the faces spell its
// ReadOptions::FIELD names as their flags and keywords).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "../support/test_data.h"

namespace cheval::traj {
namespace {

struct BadFile {
  const char* name;      // under tests/data/bad
  const char* format;    // --format
  const char* location;  // ":LINE:COLUMN"
  const char* message;   // after "error: "
};

const BadFile kBadFiles[] = {
    {"empty.txt", "auto", ":1:1", "no poses: expected at least one row of data (the file is empty or only comments)"},
    {"empty.txt", "tum", ":1:1", "no poses: expected at least one row of data (t x y z qx qy qz qw)"},
    {"only_comments.txt", "auto", ":4:1",
     "no poses: expected at least one row of data (the file is empty or only comments)"},
    {"wrong_field_count.txt", "auto", ":3:16", "expected 8 fields (t x y z qx qy qz qw), got 7"},
    {"too_many_fields.txt", "tum", ":1:19", "expected 8 fields (t x y z qx qy qz qw), got 9"},
    {"too_many_fields.txt", "auto", ":1:1",
     "cannot detect the format: 9 space-separated fields; expected 8 (tum: t x y z qx qy qz qw), 11 (tumv: ... vx "
     "vy vz), 12 (kitti) or 14 (tumv: ... vx vy vz wx wy wz). Use ReadOptions::format csv ReadOptions::columns ..."},
    {"not_a_number.txt", "auto", ":2:7", "expected a number for field 3 (y), got 'abc'"},
    {"nan.txt", "auto", ":1:9", "field 4 (z) is 'nan'; expected a finite number"},
    {"inf.txt", "auto", ":2:5", "field 2 (x) is 'inf'; expected a finite number"},
    {"truncated_last_line.txt", "auto", ":2:12",
     "truncated last line (no newline at end of file): expected 8 fields (t x y z qx qy qz qw), got 5"},
    {"zero_quaternion.txt", "auto", ":2:11", "quaternion (qx qy qz qw) has zero norm; expected a rotation"},
    {"bad_stamp.txt", "auto", ":1:1", "expected a time stamp in seconds for field 1 (t), got '12a.5'"},
    {"stamp_out_of_range.txt", "auto", ":1:1",
     "time stamp '1e12' in field 1 (t) is out of range (int64 nanoseconds, about ±292 years)"},
    {"euroc_bad_count.csv", "auto", ":2:36",
     "expected 8 fields (t_ns px py pz qw qx qy qz) or at least 11 (... vx vy vz), got 9"},
    {"euroc_fractional_ns.csv", "auto", ":3:1",
     "expected an integer number of nanoseconds for field 1 (t_ns), got '1403715524912143168.5'"},
    {"empty_field.csv", "auto", ":2:23", "field 3 (py) is empty; expected a number"},
    {"kitti_not_rotation.txt", "auto", ":2:1",
     "expected a rotation matrix in fields 1-3, 5-7, 9-11 (r00..r22), got determinant 0"},
    {"vins_wrong_count.csv", "vins", ":1:39",
     "expected 8 fields (t_ns px py pz qw qx qy qz) or 11 (... vx vy vz), got 10"},
    {"vins_wrong_count.csv", "auto", ":1:1",
     "cannot detect the format: 10 comma-separated fields; EuRoC needs a '#timestamp' or '#time' header, VINS integer "
     "nanosecond stamps and 8 or 11 fields. Use ReadOptions::format csv ReadOptions::columns ... (e.g. t_ns,px,py,pz,qw,qx,qy,qz)"},
    {"undetectable.txt", "auto", ":1:1",
     "cannot detect the format: 5 space-separated fields; expected 8 (tum: t x y z qx qy qz qw), 11 (tumv: ... vx "
     "vy vz), 12 (kitti) or 14 (tumv: ... vx vy vz wx wy wz). Use ReadOptions::format csv ReadOptions::columns ..."},
    {"header_only_csv.csv", "auto", ":2:1",
     "cannot detect the format: 4 comma-separated fields after a header row; EuRoC needs a '#timestamp' or '#time' header, VINS "
     "integer nanosecond stamps and 8 or 11 fields. Use ReadOptions::format csv ReadOptions::columns ... (e.g. t_ns,px,py,pz,qw,qx,qy,qz)"},
    {"wrong_field_count.txt", "kitti", ":1:18", "expected 12 fields (r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz), got 8"},
    // 1e400 is a finite decimal but no double: say so rather than only "expected a finite number".
    {"number_overflow.txt", "auto", ":2:5",
     "field 2 (x) is '1e400', too large for a double (at most 1.8e308 in magnitude); expected a finite number"},
    // EuRoC's bias columns are not used, but garbage there is a broken file, not something to skip.
    {"euroc_bad_bias.csv", "auto", ":3:49", "expected a number for field 14 (bwz), got 'a'"},
    {"euroc_bad_bias.csv", "euroc", ":3:49", "expected a number for field 14 (bwz), got 'a'"},
    // A header row that names another layout (w first) is not taken for TUM's order.
    {"tum_header_w_first.txt", "auto", ":1:9",
     "cannot detect the format: 8 space-separated fields after a header row that does not name tum's columns (t x "
     "y z qx qy qz qw: a time first, then names ending in x y z x y z w); its field 5 is 'qw'. Use ReadOptions::format tum if "
     "the columns are in that order, else ReadOptions::format csv ReadOptions::columns ..."},
    {"kitti_header.txt", "auto", ":2:1",
     "cannot detect the format: 12 space-separated fields after a header row; KITTI files have no header. Use "
     "ReadOptions::format kitti if this is one, else ReadOptions::format csv ReadOptions::columns ..."},
};

class BadInputTest : public ::testing::TestWithParam<BadFile> {};

TEST_P(BadInputTest, ThrowsTheExactMessage) {
  const BadFile& bad = GetParam();
  const std::string path = cheval::testing::FixturePath(std::string("bad/") + bad.name);
  ReadOptions options;
  options.format = *FormatFromString(bad.format);
  try {
    ReadTrajectory(path, options);
    FAIL() << "no error for " << bad.name;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + bad.location + ": error: " + bad.message);
    EXPECT_EQ(e.path(), path);
  }
}

std::string TestName(const ::testing::TestParamInfo<BadFile>& info) {
  std::string name = std::to_string(info.index) + "_" + info.param.name + "_" + info.param.format;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(BadFiles, BadInputTest, ::testing::ValuesIn(kBadFiles), TestName);

TEST(BadInput, MissingFile) {
  const std::string path = cheval::testing::FixturePath("bad/does_not_exist.txt");
  try {
    ReadTrajectory(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":0:0: error: cannot open file: No such file or directory");
  }
}

TEST(BadInput, KittiTimesOfAnotherLength) {
  ReadOptions options;
  options.kitti_times_path = cheval::testing::FixturePath("bad/kitti_three_times.txt");
  const std::string poses = cheval::testing::FixturePath("bad/kitti_two_poses.txt");
  try {
    ReadTrajectory(poses, options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), options.kitti_times_path + ":0:0: error: has 3 stamps but the KITTI poses file " +
                                         poses + " has 2 poses; expected one stamp per pose");
  }
}

// Inputs at the edge that the fuzz run flagged (docs/fuzzing.md) and that read on purpose.

// A decimal below half the smallest subnormal rounds to ±0, as strtod, Python's float() and
// numpy.loadtxt (evo) read it; it is not an error, and the sign survives.
TEST(EdgeInput, NumberThatUnderflowsReadsAsSignedZero) {
  const std::string tiny = "0." + std::string(400, '0') + "1";  // 1e-401 written out, no exponent
  const Trajectory t = ParseTrajectory("1.0 1e-400 -1e-400 " + tiny + " 0 0 -2.5e-99999999999999999999 1\n",
                                       "underflow.txt");
  ASSERT_EQ(t.size(), 1);
  const double* p = t.raw_positions().data();
  EXPECT_EQ(p[0], 0.0);
  EXPECT_FALSE(std::signbit(p[0]));
  EXPECT_EQ(p[1], 0.0);
  EXPECT_TRUE(std::signbit(p[1]));
  EXPECT_EQ(p[2], 0.0);
  EXPECT_TRUE(std::signbit(t.raw_orientations()[2]));
  // The smallest subnormal and numbers near the top of the range are unaffected.
  const Trajectory edge = ParseTrajectory("1.0 4.9e-324 1.7e308 -1.7e308 0 0 0 1\n", "edge.txt");
  EXPECT_EQ(edge.raw_positions()[0], std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(edge.raw_positions()[1], 1.7e308);
  EXPECT_EQ(edge.raw_positions()[2], -1.7e308);
}

TEST(EdgeInput, OverflowWithTrailingGarbageIsNotANumber) {
  try {
    ParseTrajectory("1.0 1e400abc 0 0 0 0 0 1\n", "garbage.txt");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "garbage.txt:1:5: error: expected a number for field 2 (x), got '1e400abc'");
  }
}

// A header row in TUM's order (quoted or not, with or without velocity) no longer stops detection,
// as the tum/tumv readers skip it anyway.
TEST(EdgeInput, WhitespaceHeaderInTumOrderIsDetected) {
  EXPECT_EQ(DetectFormat("h.txt", "timestamp tx ty tz qx qy qz qw\n1.0 0 0 0 0 0 0 1\n"), Format::kTum);
  EXPECT_EQ(DetectFormat("h.txt", "\"t\"\t\"p_x\"\t\"p_y\"\t\"p_z\"\t\"q_x\"\t\"q_y\"\t\"q_z\"\t\"q_w\"\t"
                                  "\"v_x\"\t\"v_y\"\t\"v_z\"\n1.0 0 0 0 0 0 0 1 0 0 0\n"),
            Format::kTumV);
  Format format_read = Format::kAuto;
  const Trajectory t = ParseTrajectory("time x y z qx qy qz qw\n1.0 1 2 3 0 0 0 1\n", "h.txt", {}, &format_read);
  EXPECT_EQ(format_read, Format::kTum);
  ASSERT_EQ(t.size(), 1);
  EXPECT_EQ(t.raw_positions(), (std::vector<double>{1, 2, 3}));
  // An IMU log has 8 columns too; its names give it away.
  try {
    DetectFormat("imu.txt", "t_s gyro_x gyro_y gyro_z acc_x acc_y acc_z thrust\n0.0 0 0 0 0 0 9.81 1\n");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 1);
    EXPECT_EQ(e.column(), 44);
    EXPECT_NE(e.detail().find("its field 8 is 'thrust'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cheval::traj

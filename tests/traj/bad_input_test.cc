// The broken files of tests/data/bad, each with the exact message a user sees.
#include <string>

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
     "vy vz) or 12 (kitti). Use --format csv --columns ..."},
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
     "nanosecond stamps and 8 or 11 fields. Use --format csv --columns ... (e.g. t_ns,px,py,pz,qw,qx,qy,qz)"},
    {"undetectable.txt", "auto", ":1:1",
     "cannot detect the format: 5 space-separated fields; expected 8 (tum: t x y z qx qy qz qw), 11 (tumv: ... vx "
     "vy vz) or 12 (kitti). Use --format csv --columns ..."},
    {"header_only_csv.csv", "auto", ":2:1",
     "cannot detect the format: 4 comma-separated fields after a header row; EuRoC needs a '#timestamp' or '#time' header, VINS "
     "integer nanosecond stamps and 8 or 11 fields. Use --format csv --columns ... (e.g. t_ns,px,py,pz,qw,qx,qy,qz)"},
    {"wrong_field_count.txt", "kitti", ":1:18", "expected 12 fields (r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz), got 8"},
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

}  // namespace
}  // namespace cheval::traj

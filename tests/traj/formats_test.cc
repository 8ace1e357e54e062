// Writers and readers agree (write -> read round trips are exact), detection picks the right
// format, and the generic column map reads what it is told to.
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/sim/motion.h"
#include "cheval/traj/io.h"

namespace cheval::traj {
namespace {

Trajectory Motion() {
  sim::MotionOptions options;
  options.duration_s = 2.0;
  options.rate_hz = 50.0;
  return sim::GenerateMotion(options);
}

void ExpectSameStampsAndPositions(const Trajectory& a, const Trajectory& b) {
  ASSERT_EQ(a.size(), b.size());
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.stamps_ns()[i], b.stamps_ns()[i]);
    // Shortest round-trip printing: the doubles come back bit for bit.
    EXPECT_EQ(a.positions().col(i), b.positions().col(i));
  }
}

TEST(Formats, TumRoundTripIsExact) {
  const Trajectory truth = Motion();
  const std::string text = FormatTrajectory(truth.View(), Format::kTum);
  Format detected = Format::kAuto;
  const Trajectory back = ParseTrajectory(text, "memory.txt", {}, &detected);
  EXPECT_EQ(detected, Format::kTum);
  ExpectSameStampsAndPositions(truth, back);
  EXPECT_EQ(truth.View().quaternions(), back.View().quaternions());
  EXPECT_FALSE(back.View().has_velocity());
}

TEST(Formats, TumVelocityRoundTripIsExact) {
  const Trajectory truth = Motion();
  Format detected = Format::kAuto;
  const Trajectory back = ParseTrajectory(FormatTrajectory(truth.View(), Format::kTumV), "m.txt", {}, &detected);
  EXPECT_EQ(detected, Format::kTumV);
  ExpectSameStampsAndPositions(truth, back);
  EXPECT_EQ(truth.View().velocities(), back.View().velocities());
}

// What the sink throws (a full disk) comes out of FormatTrajectory, the worker joined.
TEST(Formats, ASinkThatThrowsStopsTheBlocks) {
  sim::MotionOptions options;
  options.duration_s = 60.0;
  options.rate_hz = 200.0;
  const Trajectory truth = sim::GenerateMotion(options);
  int blocks = 0;
  EXPECT_THROW(FormatTrajectory(truth.View(), Format::kTum,
                                [&](std::string_view) {
                                  if (++blocks == 2) throw std::runtime_error("disk full");
                                }),
               std::runtime_error);
  EXPECT_EQ(blocks, 2);
}

TEST(Formats, EurocRoundTripIsExact) {
  const Trajectory truth = Motion();
  const std::string text = FormatTrajectory(truth.View(), Format::kEuroc);
  EXPECT_EQ(text.rfind("#timestamp [ns],p_RS_R_x [m]", 0), 0u);
  Format detected = Format::kAuto;
  const Trajectory back = ParseTrajectory(text, "m.csv", {}, &detected);
  EXPECT_EQ(detected, Format::kEuroc);
  ExpectSameStampsAndPositions(truth, back);
  EXPECT_EQ(truth.View().quaternions(), back.View().quaternions());
  EXPECT_EQ(truth.View().velocities(), back.View().velocities());
}

TEST(Formats, KittiRoundTripKeepsRotations) {
  const Trajectory truth = Motion();
  Format detected = Format::kAuto;
  const Trajectory back = ParseTrajectory(FormatTrajectory(truth.View(), Format::kKitti), "m.txt", {}, &detected);
  EXPECT_EQ(detected, Format::kKitti);
  ASSERT_EQ(back.size(), truth.size());
  EXPECT_FALSE(back.channels().has_stamps);
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(back.positions().col(i), truth.positions().col(i));
    EXPECT_EQ(back.Rotation(i), truth.Rotation(i));  // the matrix is written and read back bit for bit
  }
  // KITTI -> TUM converts the matrix to a unit quaternion of the same rotation.
  const Trajectory tum = ParseTrajectory(FormatTrajectory(back.View(), Format::kTum), "m.txt");
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    EXPECT_TRUE(tum.Rotation(i).isApprox(truth.Rotation(i), 1e-14));
  }
}

TEST(Formats, WriterRefusesWhatTheFormatCannotHold) {
  Trajectory positions_only(Channels{OrientationKind::kNone, false, false, true});
  const double p[3] = {1, 2, 3};
  positions_only.Append(0, p);
  EXPECT_THROW(FormatTrajectory(positions_only.View(), Format::kTum), ComputeError);
  const Trajectory no_velocity = ParseTrajectory("1 0 0 0 0 0 0 1\n", "m.txt");
  EXPECT_THROW(FormatTrajectory(no_velocity.View(), Format::kTumV), ComputeError);
  EXPECT_THROW(FormatTrajectory(no_velocity.View(), Format::kVins), UsageError);
}

// The writers' blocks (about 1 MiB each, for outputs too large to hold whole) join to the text that
// FormatTrajectory returns, in every format; a trajectory a format cannot hold throws before the
// first block.
// Every other block is formatted on a worker thread (with a second core): the blocks, handed over
// in order, are the whole text, also with an odd number of them (tumv).
TEST(Formats, BlocksJoinToTheWholeText) {
  sim::MotionOptions options;
  options.duration_s = 120.0;
  options.rate_hz = 100.0;  // 12001 poses: several blocks in every format
  Trajectory truth = sim::GenerateMotion(options);
  for (const Format format : {Format::kTum, Format::kTumV, Format::kEuroc, Format::kKitti}) {
    std::string joined;
    int blocks = 0;
    FormatTrajectory(truth.View(), format, [&](std::string_view block) {
      EXPECT_FALSE(block.empty());
      EXPECT_EQ(block.back(), '\n');  // whole lines only
      joined += block;
      ++blocks;
    });
    EXPECT_GT(blocks, 1) << ToString(format);
    EXPECT_EQ(joined, FormatTrajectory(truth.View(), format)) << ToString(format);
  }
  const Trajectory no_velocity = ParseTrajectory("1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n", "m.txt");
  int pieces = 0;
  EXPECT_THROW(FormatTrajectory(no_velocity.View(), Format::kTumV, [&](std::string_view) { ++pieces; }), ComputeError);
  EXPECT_EQ(pieces, 0);
}

TEST(Detect, ByContent) {
  EXPECT_EQ(DetectFormat("a", "# c\n1 0 0 0 0 0 0 1\n"), Format::kTum);
  EXPECT_EQ(DetectFormat("a", "1\t0  0 0 0 0 0 1 4 5 6\n"), Format::kTumV);
  EXPECT_EQ(DetectFormat("a", "1 0 0 0 0 1 0 0 0 0 1 0\n"), Format::kKitti);
  EXPECT_EQ(DetectFormat("a", "#timestamp, p_RS_R_x [m]\n1,0,0,0,1,0,0,0\n"), Format::kEuroc);
  EXPECT_EQ(DetectFormat("a", "1403636582163555328,0,0,0,1,0,0,0,0,0,0,\n"), Format::kVins);
  EXPECT_EQ(DetectFormat("a", "1403636582163555328,0,0,0,1,0,0,0,\n"), Format::kVins);
  EXPECT_THROW(DetectFormat("a", "1.5,0,0,0,1,0,0,0\n"), InputError);  // not ns stamps: ambiguous
  EXPECT_THROW(DetectFormat("a", "t,x,y,z\n1,2,3,4\n"), InputError);
}

TEST(ColumnMap, ParsesAndValidates) {
  const ColumnMap map = ColumnMap::Parse("t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz,_,_");
  EXPECT_EQ(map.roles.size(), 11u);  // trailing skips are dropped
  EXPECT_EQ(map.ToString(), "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz");
  EXPECT_THROW(ColumnMap::Parse("px,py,pz"), UsageError);            // no time
  EXPECT_THROW(ColumnMap::Parse("t,t_ns,px,py,pz"), UsageError);     // two times
  EXPECT_THROW(ColumnMap::Parse("t,px,py"), UsageError);             // no pz
  EXPECT_THROW(ColumnMap::Parse("t,px,py,pz,qx,qy,qz"), UsageError); // no qw
  EXPECT_THROW(ColumnMap::Parse("t,px,py,pz,qx,qy,qz,qw,roll,pitch,yaw"), UsageError);
  EXPECT_THROW(ColumnMap::Parse("t,px,py,pz,vx"), UsageError);
  EXPECT_THROW(ColumnMap::Parse("t,px,px,py,pz"), UsageError);
  EXPECT_THROW(ColumnMap::Parse("t,px,py,pz,speed"), UsageError);
  try {
    ColumnMap::Parse("t,px,py,pz,speed");
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown column role 'speed' (position 5)"), std::string::npos);
  }
}

TEST(GenericCsv, HeaderSkipsEulerAnglesAndPositionOnly) {
  ReadOptions options;
  options.format = Format::kCsv;
  options.columns = ColumnMap::Parse("t,px,py,pz,roll,pitch,yaw");
  const std::string text = "t_s,x,y,z,roll,pitch,yaw,extra\n10.5,1,2,3,0,0,1.5707963267948966,9\n";
  const Trajectory t = ParseTrajectory(text, "m.csv", options);
  ASSERT_EQ(t.size(), 1);
  EXPECT_EQ(t.stamps_ns()[0], 10500000000LL);
  // yaw of +90°: body x points along world y.
  EXPECT_TRUE((t.Rotation(0) * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-15));

  options.columns = ColumnMap::Parse("t_ms,_,px,py,pz");
  const Trajectory p = ParseTrajectory("1500 skip-me 1 2 3\n", "m.txt", options);
  EXPECT_FALSE(p.View().has_orientation());
  EXPECT_EQ(p.stamps_ns()[0], 1500000000LL);
  EXPECT_EQ(p.positions().col(0), Eigen::Vector3d(1, 2, 3));
}

TEST(GenericCsv, RollPitchYawIsZyx) {
  ReadOptions options;
  options.format = Format::kCsv;
  options.columns = ColumnMap::Parse("t,px,py,pz,roll,pitch,yaw");
  const Trajectory t = ParseTrajectory("0,0,0,0,0.1,-0.2,0.3\n", "m.csv", options);
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_TRUE(t.Rotation(0).isApprox(expected, 1e-15));
}

TEST(Readers, KeepDuplicateAndDecreasingStampsInFileOrder) {
  const Trajectory t = ParseTrajectory("2 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n1 2 0 0 0 0 0 1\n", "m.txt");
  ASSERT_EQ(t.size(), 3);
  EXPECT_EQ(t.stamps_ns()[0], 2000000000LL);
  EXPECT_EQ(t.stamps_ns()[1], 1000000000LL);
  EXPECT_EQ(t.positions()(0, 2), 2.0);
}

TEST(Readers, LenientWhitespaceCrlfAndTrailingComma) {
  const Trajectory tum = ParseTrajectory("  1\t0  0 0 0 0 0 1  \r\n\n# c\n2 0 0 0 0 0 0 1", "m.txt");
  EXPECT_EQ(tum.size(), 2);  // the last line has no newline but is complete
  const Trajectory euroc = ParseTrajectory("#timestamp\n1, 2, 3, 4, 1, 0, 0, 0,\n", "m.csv");
  EXPECT_EQ(euroc.positions().col(0), Eigen::Vector3d(2, 3, 4));
  EXPECT_EQ(euroc.stamps_ns()[0], 1);
}

TEST(Readers, EurocWithBiasesHasVelocity) {
  const Trajectory t = ParseTrajectory(
      "#timestamp\n1403715524907143168,1,2,3,1,0,0,0,4,5,6,0,0,0,0,0,0\n1403715524912143168,1,2,3,1,0,0,0,7,8,9,0,0,0,0,0,0\n",
      "gt.csv");
  ASSERT_TRUE(t.View().has_velocity());
  EXPECT_EQ(t.View().velocities().col(1), Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(t.View().quaternions().col(0), Eigen::Vector4d(0, 0, 0, 1));  // w first in the file
}

}  // namespace
}  // namespace cheval::traj

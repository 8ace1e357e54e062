#include "cheval/traj/summary.h"

#include <gtest/gtest.h>

#include "cheval/traj/io.h"

namespace cheval::traj {
namespace {

TEST(Summarize, HandCheckedExample) {
  // Stamps 0, 0.1, 0.2, 0.2 (duplicate), 0.3, 1.0 (gap), 0.9 (backwards); x moves 0,1,2,2,3,4,4.
  const Trajectory t = ParseTrajectory(
      "0.0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n"
      "0.3 3 0 0 0 0 0 2\n1.0 4 0 0 0 0 0 1\n0.9 4 0 0 0 0 0 1\n",
      "m.txt");
  const TrajectorySummary s = Summarize(t.View());
  EXPECT_EQ(s.poses, 7);
  EXPECT_DOUBLE_EQ(s.duration_s, 0.9);
  EXPECT_DOUBLE_EQ(s.rate_hz, 6 / 0.9);
  EXPECT_DOUBLE_EQ(s.path_length_m, 4.0);
  EXPECT_EQ(s.duplicate_stamps, 1);
  EXPECT_EQ(s.non_increasing_stamps, 2);
  // Positive dts: 0.1, 0.1, 0.1, 0.7 -> median 0.1; one gap (0.7 > 0.2) after stamp 0.3.
  EXPECT_EQ(s.dt_s.n, 4);
  EXPECT_NEAR(s.dt_s.median, 0.1, 1e-15);
  EXPECT_EQ(s.gaps, 1);
  EXPECT_NEAR(s.largest_gap_s, 0.7, 1e-15);
  EXPECT_EQ(s.largest_gap_after_ns, 300000000);
  // Finite-difference speeds over positive dt: 10, 10, 10, 1/0.7.
  EXPECT_NEAR(s.speed_mps.max, 10.0, 1e-12);
  EXPECT_NEAR(s.speed_mps.median, 10.0, 1e-12);
  EXPECT_FALSE(s.speed_from_velocity);
  EXPECT_EQ(s.non_unit_quaternions, 1);  // (0 0 0 2)
  EXPECT_DOUBLE_EQ(s.max_quaternion_norm_error, 1.0);
}

TEST(ComputeBasicStats, EvenCountMedianAndPopulationStd) {
  const BasicStats s = ComputeBasicStats({4, 1, 3, 2});
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_EQ(s.min, 1);
  EXPECT_EQ(s.max, 4);
  EXPECT_EQ(ComputeBasicStats({}).n, 0);
}

}  // namespace
}  // namespace cheval::traj

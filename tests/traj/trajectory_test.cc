#include "cheval/traj/trajectory.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace cheval::traj {
namespace {

Trajectory ThreePoses() {
  Trajectory t(Channels{OrientationKind::kQuaternion, true, false, true});
  const double p[3][3] = {{0, 0, 0}, {1, 2, 3}, {4, 5, 6}};
  const double q[3][4] = {{0, 0, 0, 1}, {0, 0, 0.6, 0.8}, {0, 0, 0, 2}};  // last one is not unit
  const double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i) t.Append(1000 + i, p[i], q[i], v[i]);
  return t;
}

TEST(Trajectory, StoresChannelsContiguously) {
  const Trajectory t = ThreePoses();
  ASSERT_EQ(t.size(), 3);
  EXPECT_EQ(t.stamps_ns()[2], 1002);
  EXPECT_EQ(t.positions().col(1), Eigen::Vector3d(1, 2, 3));
  // Column i of the map is the i-th triple of the raw storage: numpy can see it as (n, 3).
  EXPECT_EQ(t.positions().data(), t.raw_positions().data());
  EXPECT_EQ(t.raw_positions()[5], 3.0);
  EXPECT_EQ(t.View().velocities().col(2), Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(t.View().quaternions().col(1), Eigen::Vector4d(0, 0, 0.6, 0.8));  // as read
}

TEST(Trajectory, SliceIsAViewWithoutCopy) {
  const Trajectory t = ThreePoses();
  const TrajectoryView tail = t.View(1, 3);
  ASSERT_EQ(tail.size(), 2);
  EXPECT_EQ(tail.stamps_ns()[0], 1001);
  EXPECT_EQ(tail.positions().data(), t.raw_positions().data() + 3);
  EXPECT_EQ(tail.velocities().col(0), Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(tail.Slice(1, 2).positions().col(0), Eigen::Vector3d(4, 5, 6));
  EXPECT_TRUE(t.View(3, 3).empty());
  EXPECT_THROW(t.View(2, 4), std::out_of_range);
}

TEST(Trajectory, RotationNormalisesLikeEvo) {
  const Trajectory t = ThreePoses();
  // (0, 0, 0.6, 0.8) is a rotation about z by 2·atan2(0.6, 0.8).
  const double angle = 2 * std::atan2(0.6, 0.8);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(t.Rotation(1).isApprox(expected, 1e-15));
  // A non-unit quaternion is normalised: (0, 0, 0, 2) is the identity.
  EXPECT_TRUE(t.Rotation(2).isApprox(Eigen::Matrix3d::Identity(), 1e-15));
  EXPECT_NEAR(t.View().UnitQuaternion(2).w(), 1.0, 1e-15);
}

TEST(RotationFromQuaternion, MatchesEigenOnRandomUnitQuaternionsAndScales) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 1000; ++i) {
    Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    const double scale = std::exp(normal(rng));
    const Eigen::Matrix3d expected = q.normalized().toRotationMatrix();
    const Eigen::Matrix3d actual = RotationFromQuaternion(scale * q.x(), scale * q.y(), scale * q.z(), scale * q.w());
    // Both are O(1) expressions of normalised products; a few ulps of difference.
    EXPECT_TRUE(actual.isApprox(expected, 1e-14)) << actual << "\n" << expected;
  }
  EXPECT_EQ(RotationFromQuaternion(0, 0, 0, 1e-9), Eigen::Matrix3d::Identity());  // evo: below 4 eps -> identity
}

TEST(Trajectory, KittiMatricesAreKeptAsRead) {
  Trajectory t(Channels{OrientationKind::kMatrix, false, false, false});
  const double R[9] = {1.0, 1e-6, 0, 0, 0.999999, 0, 0, 0, 1};  // slightly off, as KITTI's are
  const double p[3] = {1, 2, 3};
  t.Append(0, p, R);
  EXPECT_EQ(t.Rotation(0)(0, 1), 1e-6);
  EXPECT_EQ(t.Rotation(0)(1, 1), 0.999999);
  EXPECT_FALSE(t.channels().has_stamps);
}

TEST(Trajectory, SetVelocitiesAddsTheChannel) {
  Trajectory t(Channels{OrientationKind::kNone, false, false, true});
  const double p[3] = {0, 0, 0};
  t.Append(0, p);
  t.Append(1, p);
  EXPECT_FALSE(t.View().has_velocity());
  Eigen::Matrix3Xd v(3, 2);
  v << 1, 2, 3, 4, 5, 6;
  t.SetVelocities(v);
  EXPECT_TRUE(t.View().has_velocity());
  EXPECT_EQ(t.View().velocities().col(1), Eigen::Vector3d(2, 4, 6));
  EXPECT_THROW(t.SetVelocities(Eigen::Matrix3Xd(3, 3)), std::invalid_argument);
}

}  // namespace
}  // namespace cheval::traj

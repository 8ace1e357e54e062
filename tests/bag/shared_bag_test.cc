// The shared recordings (../shared/data/evo, SOURCE.md there): topic counts, first/last stamps and
// APE numbers equal to what the same poses give from TUM files exported by an independent reader
// (a 40-line Python parser of the ROS 1 records and of MCAP with the zstd tool, written for this
// check; its TUM files read by cheval's TUM reader gave the APE figures below).
#include <string>

#include <gtest/gtest.h>

#include "cheval/bag/bag.h"
#include "cheval/eval/evaluate.h"
#include "../support/test_data.h"

namespace cheval::bag {
namespace {

std::string Evo(const std::string& name) { return ::cheval::testing::SharedDataDir() + "/evo/" + name; }

TEST(SharedBags, RosExampleTopicsCountsAndStamps) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::vector<TopicInfo> topics = ListTopics(Evo("ROS_example.bag"));
  ASSERT_EQ(topics.size(), 3u);
  EXPECT_EQ(topics[0].name, "ORB-SLAM");
  EXPECT_EQ(topics[0].count, 8362);
  EXPECT_EQ(topics[1].name, "S-PTAM");
  EXPECT_EQ(topics[1].count, 5439);
  EXPECT_EQ(topics[2].name, "groundtruth");
  EXPECT_EQ(topics[2].count, 12765);
  for (const TopicInfo& t : topics) EXPECT_EQ(t.type, "geometry_msgs/PoseStamped");

  struct Expected {
    const char* topic;
    Eigen::Index poses;
    int64_t first, last;
  };
  for (const Expected& e : {Expected{"groundtruth", 12765, 1502792570283404827LL, 1502793459302349567LL},
                            Expected{"S-PTAM", 5439, 1502792579887224912LL, 1502793310833494186LL},
                            Expected{"ORB-SLAM", 8362, 1502792579827646017LL, 1502793310627640008LL}}) {
    const traj::Trajectory t = ReadBagTrajectory(Evo("ROS_example.bag"), {e.topic, false});
    EXPECT_EQ(t.size(), e.poses) << e.topic;
    EXPECT_EQ(t.stamps_ns().front(), e.first) << e.topic;
    EXPECT_EQ(t.stamps_ns().back(), e.last) << e.topic;
  }
}

TEST(SharedBags, RosExampleApeEqualsTheExportedTumFiles) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const traj::Trajectory ref = ReadBagTrajectory(Evo("ROS_example.bag"), {"groundtruth", false});
  struct Expected {
    const char* topic;
    eval::AlignmentMethod align;
    double rmse;
    Eigen::Index pairs;
  };
  for (const Expected& e : {Expected{"S-PTAM", eval::AlignmentMethod::kNone, 10.344660247686752, 1667},
                            Expected{"S-PTAM", eval::AlignmentMethod::kSE3, 6.316709599487176, 1667},
                            Expected{"S-PTAM", eval::AlignmentMethod::kSim3, 6.28182645363752, 1667},
                            Expected{"ORB-SLAM", eval::AlignmentMethod::kNone, 8.508008262610987, 2550},
                            Expected{"ORB-SLAM", eval::AlignmentMethod::kSE3, 5.509938188274031, 2550},
                            Expected{"ORB-SLAM", eval::AlignmentMethod::kSim3, 5.404706518895514, 2550}}) {
    const traj::Trajectory est = ReadBagTrajectory(Evo("ROS_example.bag"), {e.topic, false});
    eval::EvaluationOptions options;
    options.alignment.method = e.align;
    const eval::EvaluationResult r = eval::Evaluate(ref.View(), est.View(), options);
    EXPECT_EQ(r.stats.n, e.pairs) << e.topic;
    EXPECT_NEAR(r.stats.rmse, e.rmse, 1e-12 * e.rmse) << e.topic << " " << eval::ToString(e.align);
  }
}

TEST(SharedBags, Nav2McapCountsStampsAndOdometryVelocity) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const std::vector<TopicInfo> topics = ListTopics(Evo("nav2_turtlebot.mcap"));
  ASSERT_EQ(topics.size(), 4u);
  EXPECT_EQ(topics[0].name, "/amcl_pose");
  EXPECT_EQ(topics[0].count, 135);
  EXPECT_EQ(topics[1].count, 2639);
  EXPECT_EQ(topics[2].count, 5422);
  EXPECT_EQ(topics[3].count, 1);
  const traj::Trajectory amcl = ReadBagTrajectory(Evo("nav2_turtlebot.mcap"), {"/amcl_pose", false});
  EXPECT_EQ(amcl.size(), 135);
  EXPECT_EQ(amcl.stamps_ns().front(), 924102000000LL);
  EXPECT_EQ(amcl.stamps_ns().back(), 1023300000000LL);
  const traj::Trajectory odom = ReadBagTrajectory(Evo("nav2_turtlebot.mcap"), {"/odom", false});
  EXPECT_EQ(odom.size(), 2639);
  EXPECT_EQ(odom.stamps_ns().front(), 928800000000LL);
  EXPECT_EQ(odom.stamps_ns().back(), 1025496000000LL);
  ASSERT_TRUE(odom.channels().velocity);
  // A ground robot: the world-frame velocity is horizontal and at most the 0.5 m/s it was driven at.
  const auto v = odom.View().velocities();
  EXPECT_LE(v.colwise().norm().maxCoeff(), 0.5 + 1e-9);
  EXPECT_LE(v.row(2).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace cheval::bag

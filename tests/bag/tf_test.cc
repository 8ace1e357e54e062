// tf chains read as evo reads them (evo/tools/tf_cache.py on tf2's BufferCore), on recordings
// bag::WriteBag makes in every container, built so that another rule gives another answer: the
// lookup times (the recording's start, every 0.1 s, up to the latest common time), the times
// skipped (before an edge's first transform), the static transform (the last one), the static-only
// chain (one pose at stamp 0), interpolation between transforms; and the shared evo bags.

#include <cmath>
#include <filesystem>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "cheval/bag/bag.h"
#include "cheval/common/error.h"
#include "tf.h"
#include "tf_buffer.h"
#include "../support/test_data.h"

#ifndef CHEVAL_DATA_DIR
#define CHEVAL_DATA_DIR ""
#endif

namespace cheval::bag {
namespace {

constexpr int64_t kS = 1000000000;        // one second in ns
constexpr int64_t kStart = 100 * kS + 7;  // the recording's first log time (a marker message)

PoseMessage Tf(int64_t stamp, const char* parent, const char* child, double x, double z = 0.0) {
  PoseMessage m;
  m.stamp_ns = stamp;
  m.record_time_ns = stamp + 1000000;  // logged 1 ms after its stamp
  m.frame_id = parent;
  m.child_frame_id = child;
  m.position[0] = x;
  m.position[2] = z;
  return m;
}

class TfEvo : public ::testing::TestWithParam<std::tuple<Container, std::string>> {
 protected:
  void SetUp() override {
    dir_ = testing::FreshTestDir("cheval_tf_");
    // odom -> base every 0.2 s from 100.3 s to 101.5 s, x = 10 (t - 100); base -> lidar at 100.0,
    // 100.5, 101.0 s; base -> cam static, written twice (z = 1, then z = 2). A marker on /m is the
    // recording's first message (100 s + 7 ns), so the lookup times are 100.000000007 + k 0.1 s.
    std::vector<PoseMessage> tf;
    for (int i = 0; i <= 6; ++i) {
      const int64_t t = 100 * kS + 300000000 + i * 200000000LL;
      tf.push_back(Tf(t, "odom", "base", 10.0 * static_cast<double>(t - 100 * kS) / kS));
    }
    for (int i = 0; i <= 2; ++i) tf.push_back(Tf(100 * kS + i * 500000000LL, "base", "lidar", 0.0, 1.0 + i));
    PoseMessage first = Tf(90 * kS, "base", "cam", 0.0, 1.0), second = Tf(95 * kS, "base", "cam", 0.0, 2.0);
    first.record_time_ns = 100 * kS + 100000000;
    second.record_time_ns = 100 * kS + 200000000;
    PoseMessage marker;
    marker.stamp_ns = marker.record_time_ns = kStart;
    WriteOptions options;
    options.container = std::get<0>(GetParam());
    options.compression = std::get<1>(GetParam());
    options.messages_per_chunk = 4;
    path_ = (dir_ / "tf").string();
    WriteBag(path_,
             {{"/m", MessageType::kPoseStamped, {marker}},
              {"/tf", MessageType::kTfMessage, tf},
              {"/tf_static", MessageType::kTfMessage, {first, second}}},
             options);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
  std::string path_;
};

TEST_P(TfEvo, LooksUpFromTheStartEvery100MsUpToTheLatestCommonTime) {
  const traj::Trajectory base = ReadBagTrajectory(path_, {"/tf:odom.base", false});
  // 100.000000007 + k 0.1 s inside [100.3, 101.5]: k = 3..14 (k = 15 is 101.500000007, past the end).
  ASSERT_EQ(base.size(), 12);
  for (Eigen::Index i = 0; i < base.size(); ++i) {
    const int64_t t = kStart + (3 + i) * 100000000LL;
    EXPECT_EQ(base.stamps_ns()[i], t);
    // Linear between the transforms around t: x = 10 (t - 100 s).
    EXPECT_NEAR(base.positions()(0, i), 10.0 * static_cast<double>(t - 100 * kS) / kS, 1e-12);
  }
}

TEST_P(TfEvo, StaticTransformIsTheLastOneAndAStaticChainIsOnePoseAtZero) {
  const traj::Trajectory cam = ReadBagTrajectory(path_, {"/tf:odom.cam", false});
  ASSERT_EQ(cam.size(), 12);  // the static edge has no latest time: odom -> base's decides
  for (Eigen::Index i = 0; i < cam.size(); ++i) EXPECT_EQ(cam.positions()(2, i), 2.0);
  const traj::Trajectory only_static = ReadBagTrajectory(path_, {"/tf:base.cam", false});
  ASSERT_EQ(only_static.size(), 1);
  EXPECT_EQ(only_static.stamps_ns()[0], 0);
  EXPECT_EQ(only_static.positions()(2, 0), 2.0);
}

TEST_P(TfEvo, TheShortestEdgeEndsTheChainAndBothSidesOfTheTreeAreWalked) {
  // odom -> lidar: base's span [100.3, 101.5] and lidar's [100.0, 101.0]; the latest common time
  // is 101.0, so k = 3..9.
  const traj::Trajectory lidar = ReadBagTrajectory(path_, {"/tf:odom.lidar", false});
  ASSERT_EQ(lidar.size(), 7);
  EXPECT_EQ(lidar.stamps_ns()[0], kStart + 300000000);
  EXPECT_EQ(lidar.stamps_ns()[6], kStart + 900000000);
  // z goes 1 -> 2 over [100.0, 100.5] and 2 -> 3 over [100.5, 101.0].
  EXPECT_NEAR(lidar.positions()(2, 0), 1.0 + (0.3 + 7e-9) / 0.5, 1e-9);
  // cam in lidar: across the tree (lidar up to base, down to cam).
  const traj::Trajectory across = ReadBagTrajectory(path_, {"/tf:lidar.cam", false});
  // Only lidar's span [100.0, 101.0] counts (k = 0..9): tf2 walks from cam up to the root, but a
  // failure above the common parent base is caught up by the walk from lidar.
  ASSERT_EQ(across.size(), 10);
  EXPECT_NEAR(across.positions()(2, 0), 2.0 - (1.0 + 7e-9 / 0.5), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Containers, TfEvo,
                         ::testing::Values(std::make_tuple(Container::kRos1, "none"),
                                           std::make_tuple(Container::kRos1, "bz2"),
                                           std::make_tuple(Container::kMcap, "zstd"),
                                           std::make_tuple(Container::kRos2, "none")),
                         [](const ::testing::TestParamInfo<TfEvo::ParamType>& p) {
                           return std::string(ToString(std::get<0>(p.param))) + "_" + std::get<1>(p.param);
                         });

TEST(TfTopic, ParsesEvosIdentifiers) {
  const TfChain a = *ParseTfTopic("/tf:map.base.link");  // the child is all after the first '.'
  EXPECT_EQ(a.topic, "/tf");
  EXPECT_EQ(a.parent, "map");
  EXPECT_EQ(a.child, "base.link");
  EXPECT_EQ(a.static_topic, "/tf_static");
  const TfChain b = *ParseTfTopic("/tf2:/odom.base:/tf2_static");
  EXPECT_EQ(b.topic, "/tf2");
  EXPECT_EQ(b.parent, "odom");
  EXPECT_EQ(b.static_topic, "/tf2_static");
  EXPECT_FALSE(ParseTfTopic("/pose").has_value());
  EXPECT_THROW(ParseTfTopic("/tf:odom"), UsageError);
  EXPECT_THROW(ParseTfTopic("/tf:.base"), UsageError);
}

TfPose At(int64_t t, double x, double qw = 1.0) {
  TfPose p;
  p.stamp_ns = t;
  p.translation = {x, 0, 0};
  p.rotation = {0, 0, 0, qw};
  return p;
}

// tf2's caches as evo fills them; each case would come out otherwise under a simpler rule.
TEST(TfBuffer, CachesAsTf2) {
  TfBuffer buffer;
  ASSERT_TRUE(buffer.Set("a", "b", At(1 * kS, 1.0), false));
  ASSERT_TRUE(buffer.Set("/a", "b", At(2 * kS, 2.0), false));  // a leading '/' is dropped
  ASSERT_TRUE(buffer.Set("a", "b", At(2 * kS, 5.0), false));   // the same stamp again, other data
  EXPECT_FALSE(buffer.Set("a", "b", At(3 * kS, 7.0, 2.0), false));  // |q|^2 = 4: ignored
  EXPECT_FALSE(buffer.Set("b", "b", At(3 * kS, 7.0), false));       // to itself: ignored
  // a -> c dynamic, then static (evo reads /tf_static after /tf): the static one replaces it.
  ASSERT_TRUE(buffer.Set("a", "c", At(1 * kS, 3.0), false));
  ASSERT_TRUE(buffer.Set("a", "c", At(0, 9.0), true));
  buffer.Finish();
  TfPose p;
  // At the newest stamp: the last transform stamped there; between: the first one stamped there.
  ASSERT_EQ(buffer.Lookup("a", "b", 2 * kS, &p), TfStatus::kOk);
  EXPECT_EQ(p.translation.x, 5.0);
  ASSERT_EQ(buffer.Lookup("a", "b", 3 * kS / 2, &p), TfStatus::kOk);
  EXPECT_EQ(p.translation.x, 1.5);
  EXPECT_EQ(p.stamp_ns, 3 * kS / 2);
  EXPECT_EQ(buffer.Lookup("a", "b", 3 * kS, &p), TfStatus::kExtrapolation);  // the ignored one
  ASSERT_EQ(buffer.Lookup("a", "c", 5 * kS, &p), TfStatus::kOk);
  EXPECT_EQ(p.translation.x, 9.0);
  int64_t latest = -1;
  ASSERT_EQ(buffer.LatestCommonTime("b", "c", &latest), TfStatus::kOk);
  EXPECT_EQ(latest, 2 * kS);  // the static edge has no time of its own
  EXPECT_EQ(buffer.Lookup("a", "nowhere", kS, &p), TfStatus::kUnknownFrame);
}

TEST(TfBuffer, PrunesToTheCacheTime) {
  TfBuffer buffer;  // evo's 1e4 s
  ASSERT_TRUE(buffer.Set("a", "b", At(1 * kS, 1.0), false));
  ASSERT_TRUE(buffer.Set("a", "b", At(10002 * kS, 2.0), false));
  ASSERT_TRUE(buffer.Set("a", "b", At(10003 * kS, 3.0), false));  // prunes what is older than 2 s
  buffer.Finish();
  TfPose p;
  EXPECT_EQ(buffer.Lookup("a", "b", 1500 * kS, &p), TfStatus::kExtrapolation);
  EXPECT_EQ(buffer.Lookup("a", "b", 10002 * kS, &p), TfStatus::kOk);
}

// evo's tf_example (ROS 1 and ROS 2): start 1714741164.111822142 (the first log time, and the ROS 2
// metadata's starting_time), base_footprint's transforms from 1714741164.177519307 to
// 1714741215.784817334: k = 1..515, the same poses in both.
TEST(TfShared, TfExampleAsEvo) {
  const std::string dir = std::string(CHEVAL_DATA_DIR) + "/evo/";
  if (std::string(CHEVAL_DATA_DIR).empty() || !std::filesystem::exists(dir + "tf_example.bag")) {
    GTEST_SKIP() << "shared data not found";
  }
  for (const char* chain : {"/tf:odom.base_link", "/tf:odom.base_footprint"}) {
    const traj::Trajectory ros1 = ReadBagTrajectory(dir + "tf_example.bag", {chain, false});
    const traj::Trajectory ros2 = ReadBagTrajectory(dir + "tf_example", {chain, false});
    ASSERT_EQ(ros1.size(), 516) << chain;
    ASSERT_EQ(ros2.size(), 516) << chain;
    EXPECT_EQ(ros1.stamps_ns()[0], 1714741164211822142LL);
    EXPECT_EQ(ros1.stamps_ns()[515], 1714741215711822142LL);
    EXPECT_TRUE(std::equal(ros1.stamps_ns().begin(), ros1.stamps_ns().end(), ros2.stamps_ns().begin()));
    EXPECT_EQ(ros1.raw_positions(), ros2.raw_positions());
    EXPECT_EQ(ros1.raw_orientations(), ros2.raw_orientations());
    // The first lookup lies between the first two transforms, which hold the same pose.
    EXPECT_EQ(ros1.positions()(0, 0), 1.1603796887148006);
    EXPECT_EQ(ros1.positions()(1, 0), -2.942426888388735);
  }
  // base_footprint -> base_link is a static identity: both chains are the same poses.
  const traj::Trajectory link = ReadBagTrajectory(dir + "tf_example", {"/tf:odom.base_link", false});
  const traj::Trajectory footprint = ReadBagTrajectory(dir + "tf_example", {"/tf:odom.base_footprint", false});
  EXPECT_EQ(link.raw_positions(), footprint.raw_positions());
  EXPECT_EQ(link.raw_orientations(), footprint.raw_orientations());
}

}  // namespace
}  // namespace cheval::bag

// Recordings written by bag::WriteBag in every container, compression and encoding read back by
// bag::ReadBagTrajectory / traj::ReadTrajectory: every message type, stamps from headers and from the
// record time, Odometry twists turned into world-frame velocities, the last Path (tf chains: tf_test.cc).
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "cheval/bag/bag.h"
#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "../support/test_data.h"

namespace cheval::bag {
namespace {

// A test folder removed afterwards.
class TempDir {
 public:
  TempDir() {
    path_ = testing::FreshTestDir("cheval_bag_");
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// n poses along a helix, turning about z; stamps 0.1 s apart, record time 5 ms after the stamp.
std::vector<PoseMessage> Helix(int n, int64_t t0_ns = 1500000000123456789LL) {
  std::vector<PoseMessage> out;
  for (int i = 0; i < n; ++i) {
    PoseMessage m;
    m.stamp_ns = t0_ns + i * 100000000LL;
    m.record_time_ns = m.stamp_ns + 5000000;
    const double yaw = 0.1 * i;
    m.position[0] = std::cos(yaw);
    m.position[1] = std::sin(yaw);
    m.position[2] = 0.01 * i;
    m.orientation[2] = std::sin(yaw / 2);
    m.orientation[3] = std::cos(yaw / 2);
    m.linear[0] = 1.0 + 0.01 * i;  // forward in the body frame
    m.linear[1] = 0.2;
    m.angular[2] = 0.5;
    out.push_back(m);
  }
  return out;
}

void ExpectPoses(const traj::Trajectory& t, const std::vector<PoseMessage>& messages, bool record_time = false) {
  ASSERT_EQ(t.size(), static_cast<Eigen::Index>(messages.size()));
  const auto q = t.View().quaternions();
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const PoseMessage& m = messages[static_cast<size_t>(i)];
    EXPECT_EQ(t.stamps_ns()[i], record_time ? m.record_time_ns : m.stamp_ns);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(t.positions()(k, i), m.position[k]);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(q(k, i), m.orientation[k]);
  }
}

using Case = std::tuple<Container, std::string, std::string>;  // container, compression, MCAP encoding

class RoundTrip : public ::testing::TestWithParam<Case> {
 protected:
  std::string Write(const TempDir& dir, const std::vector<TopicToWrite>& topics) {
    WriteOptions options;
    options.container = std::get<0>(GetParam());
    options.compression = std::get<1>(GetParam());
    options.mcap_encoding = std::get<2>(GetParam());
    if (options.container == Container::kRos2) options.ros2_compression_mode = std::get<2>(GetParam());
    options.messages_per_chunk = 7;  // several chunks
    const std::string path = dir / (options.container == Container::kRos2 ? "bag" : "bag.bin");
    WriteBag(path, topics, options);
    return path;
  }
};

TEST_P(RoundTrip, EveryPoseTypeReadsBackExactly) {
  TempDir dir;
  const std::vector<PoseMessage> poses = Helix(40);
  const std::vector<TopicToWrite> topics = {
      {"/pose", MessageType::kPoseStamped, poses},
      {"/pose_cov", MessageType::kPoseWithCovarianceStamped, poses},
      {"/transform", MessageType::kTransformStamped, poses},
      {"/odom", MessageType::kOdometry, poses},
  };
  const std::string path = Write(dir, topics);
  EXPECT_EQ(DetectContainer(path), std::get<0>(GetParam()));
  for (const TopicToWrite& topic : topics) {
    SCOPED_TRACE(topic.name);
    ExpectPoses(ReadBagTrajectory(path, {topic.name, false}), poses);
    ExpectPoses(ReadBagTrajectory(path, {topic.name, true}), poses, true);
  }
  // Through the trajectory reader, as every face reads.
  traj::ReadOptions options;
  options.topic = "/pose";
  ExpectPoses(traj::ReadTrajectory(path, options), poses);
}

TEST_P(RoundTrip, OdometryTwistBecomesWorldFrameVelocity) {
  TempDir dir;
  const std::vector<PoseMessage> poses = Helix(20);
  const std::string path = Write(dir, {{"/odom", MessageType::kOdometry, poses}});
  const traj::Trajectory t = ReadBagTrajectory(path, {"/odom", false});
  ASSERT_TRUE(t.channels().velocity);
  ASSERT_TRUE(t.channels().angular_velocity);
  const auto v = t.View().velocities();
  const auto w = t.View().angular_velocities();
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    // Yaw 0.1 i: the body's x axis is (cos, sin, 0) in the world.
    const double yaw = 0.1 * static_cast<double>(i);
    const double vx = 1.0 + 0.01 * static_cast<double>(i), vy = 0.2;
    EXPECT_NEAR(v(0, i), std::cos(yaw) * vx - std::sin(yaw) * vy, 1e-12);
    EXPECT_NEAR(v(1, i), std::sin(yaw) * vx + std::cos(yaw) * vy, 1e-12);
    EXPECT_NEAR(v(2, i), 0.0, 1e-12);
    EXPECT_EQ(w(2, i), 0.5);  // angular velocity stays in the body frame
  }
}

TEST_P(RoundTrip, PathIsItsLastMessage) {
  TempDir dir;
  const std::vector<PoseMessage> poses = Helix(12);
  const std::string path = Write(dir, {{"/path", MessageType::kPath, poses}});
  ExpectPoses(ReadBagTrajectory(path, {"/path", false}), poses);  // the last message holds all 12
}

TEST_P(RoundTrip, TopicsAreListedWithCounts) {
  TempDir dir;
  const std::string path = Write(dir, {{"/b", MessageType::kPoseStamped, Helix(9)}, {"/a", MessageType::kOdometry, Helix(4)}});
  const std::vector<TopicInfo> topics = ListTopics(path);
  ASSERT_EQ(topics.size(), 2u);
  EXPECT_EQ(topics[0].name, "/a");
  EXPECT_EQ(topics[0].count, 4);
  EXPECT_NE(topics[0].type.find("Odometry"), std::string::npos);
  EXPECT_EQ(topics[1].name, "/b");
  EXPECT_EQ(topics[1].count, 9);
}

INSTANTIATE_TEST_SUITE_P(
    Containers, RoundTrip,
    ::testing::Values(Case{Container::kRos1, "none", "cdr"}, Case{Container::kRos1, "bz2", "cdr"},
                      Case{Container::kRos1, "lz4", "cdr"}, Case{Container::kMcap, "none", "cdr"},
                      Case{Container::kMcap, "zstd", "cdr"}, Case{Container::kMcap, "lz4", "cdr"},
                      Case{Container::kMcap, "zstd", "ros1"}, Case{Container::kMcap, "none", "ros1"},
                      Case{Container::kRos2, "none", "cdr"}, Case{Container::kRos2, "zstd", "file"},
                      Case{Container::kRos2, "zstd", "message"}),
    [](const ::testing::TestParamInfo<Case>& param) {
      return std::string(ToString(std::get<0>(param.param))) + "_" + std::get<1>(param.param) + "_" +
             std::get<2>(param.param);
    });

}  // namespace
}  // namespace cheval::bag

namespace cheval::bag {
namespace {

TEST(Ros2Folder, OfMcapFilesReadsEveryFile) {
  TempDir dir;
  const std::string folder = dir / "run";
  std::filesystem::create_directories(folder);
  const std::vector<PoseMessage> poses = Helix(30);
  WriteOptions options;
  options.container = Container::kMcap;
  options.compression = "zstd";
  WriteBag(folder + "/run_0.mcap", {{"/odom", MessageType::kOdometry, {poses.begin(), poses.begin() + 10}}}, options);
  WriteBag(folder + "/run_1.mcap", {{"/odom", MessageType::kOdometry, {poses.begin() + 10, poses.end()}}}, options);
  std::ofstream(folder + "/metadata.yaml") << "rosbag2_bagfile_information:\n  version: 8\n  storage_identifier: mcap\n"
                                              "  compression_format: ''\n  relative_file_paths:\n  - run_0.mcap\n  - run_1.mcap\n";
  EXPECT_EQ(DetectContainer(folder), Container::kRos2);
  ExpectPoses(ReadBagTrajectory(folder, {"/odom", false}), poses);
  const std::vector<TopicInfo> topics = ListTopics(folder);
  ASSERT_EQ(topics.size(), 1u);
  EXPECT_EQ(topics[0].count, 30);
}

// A FIFO is never a recording and is never opened to look: the trajectory reader opens it once
// after (a first open would take the writer's data and leave the second waiting for a writer that is
// gone; opening one without a writer here would block this test).
TEST(DetectContainer, AFifoIsNotOpened) {
  TempDir dir;
  const std::string fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(DetectContainer(fifo), Container::kNone);
}

}  // namespace
}  // namespace cheval::bag

// Recordings written by bag::WriteBag in every container, compression and encoding read back by
// bag::ReadBagTrajectory / traj::ReadTrajectory: every message type, stamps from headers and from the
// record time, Odometry twists turned into world-frame velocities, the last Path, tf chains.
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

namespace cheval::bag {
namespace {

// A test folder removed afterwards.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("cheval_bag_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
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

TEST_P(RoundTrip, TfChainThroughStaticAndDynamicEdgesInterpolated) {
  TempDir dir;
  // odom -> base_footprint dynamic at 10 Hz; base_footprint -> base_link static (a 0.3 m lift, a
  // quarter turn about x); odom -> camera dynamic at 2 Hz, on another branch of the tree.
  std::vector<PoseMessage> footprint = Helix(21);
  for (PoseMessage& m : footprint) m.frame_id = "odom", m.child_frame_id = "base_footprint";
  PoseMessage link;
  link.stamp_ns = footprint.front().stamp_ns;
  link.record_time_ns = footprint.front().record_time_ns;
  link.frame_id = "base_footprint";
  link.child_frame_id = "base_link";
  link.position[2] = 0.3;
  link.orientation[0] = std::sin(M_PI / 4);
  link.orientation[3] = std::cos(M_PI / 4);
  std::vector<PoseMessage> tf = footprint;
  std::vector<PoseMessage> camera;
  for (int i = 0; i < 5; ++i) {  // 0.5 s apart: the footprint stamps between are interpolated
    PoseMessage m;
    m.stamp_ns = footprint.front().stamp_ns + i * 500000000LL;
    m.record_time_ns = m.stamp_ns;
    m.frame_id = "odom";
    m.child_frame_id = "camera";
    m.position[0] = 2.0 * i;  // moves 4 m/s along x
    tf.push_back(m);
    camera.push_back(m);
  }
  const std::string path = Write(dir, {{"/tf", MessageType::kTfMessage, tf}, {"/tf_static", MessageType::kTfMessage, {link}}});

  const traj::Trajectory base_link = ReadBagTrajectory(path, {"/tf:odom.base_link", false});
  ASSERT_EQ(base_link.size(), 21);
  for (Eigen::Index i = 0; i < 21; ++i) {
    const PoseMessage& f = footprint[static_cast<size_t>(i)];
    EXPECT_EQ(base_link.stamps_ns()[i], f.stamp_ns);
    EXPECT_NEAR(base_link.positions()(0, i), f.position[0], 1e-12);
    EXPECT_NEAR(base_link.positions()(2, i), f.position[2] + 0.3, 1e-12);  // the lift is vertical
    const Eigen::Quaterniond expected = Eigen::Quaterniond(f.orientation[3], 0, 0, f.orientation[2]) *
                                        Eigen::Quaterniond(link.orientation[3], link.orientation[0], 0, 0);
    EXPECT_NEAR(std::abs(base_link.View().UnitQuaternion(i).dot(expected)), 1.0, 1e-12);
  }
  // camera in base_footprint, up through odom and down the other branch, at the camera's stamps.
  const traj::Trajectory cam = ReadBagTrajectory(path, {"/tf:base_footprint.camera", false});
  ASSERT_EQ(cam.size(), 5);
  // At 0.5 s the footprint pose (index 5) is interpolation-free: compare with the inverse composition.
  const PoseMessage& f5 = footprint[5];
  const Eigen::Quaterniond q5(f5.orientation[3], 0, 0, f5.orientation[2]);
  const Eigen::Vector3d expected = q5.conjugate() * (Eigen::Vector3d(2.0, 0, 0) -
                                                     Eigen::Vector3d(f5.position[0], f5.position[1], f5.position[2]));
  EXPECT_NEAR((cam.positions().col(1) - expected).norm(), 0.0, 1e-12);
  const traj::Trajectory odom_cam = ReadBagTrajectory(path, {"/tf:odom.camera", false});
  EXPECT_EQ(odom_cam.size(), 5);
}

INSTANTIATE_TEST_SUITE_P(
    Containers, RoundTrip,
    ::testing::Values(Case{Container::kRos1, "none", "cdr"}, Case{Container::kRos1, "bz2", "cdr"},
                      Case{Container::kRos1, "lz4", "cdr"}, Case{Container::kMcap, "none", "cdr"},
                      Case{Container::kMcap, "zstd", "cdr"}, Case{Container::kMcap, "lz4", "cdr"},
                      Case{Container::kMcap, "zstd", "ros1"}, Case{Container::kMcap, "none", "ros1"},
                      Case{Container::kRos2, "none", "cdr"}),
    [](const ::testing::TestParamInfo<Case>& param) {
      return std::string(ToString(std::get<0>(param.param))) + "_" + std::get<1>(param.param) + "_" +
             std::get<2>(param.param);
    });

TEST(TfChain, InterpolatesBetweenStampsOfAnotherEdge) {
  TempDir dir;
  // odom -> a at t = 0, 1 s (moving 0 -> 1 m in x); a -> b at t = 0.25 s only... and 0.75 s: b's
  // stamps lie between a's, so a's edge is interpolated at 0.25 and 0.75 s.
  auto tf = [](int64_t t, const char* parent, const char* child, double x) {
    PoseMessage m;
    m.stamp_ns = t;
    m.record_time_ns = t;
    m.frame_id = parent;
    m.child_frame_id = child;
    m.position[0] = x;
    return m;
  };
  const int64_t s = 1000000000;
  const std::vector<PoseMessage> messages = {tf(0, "odom", "a", 0.0), tf(s / 4, "a", "b", 10.0),
                                             tf(3 * s / 4, "a", "b", 20.0), tf(s, "odom", "a", 1.0)};
  const std::string path = dir / "tf.bag";
  WriteBag(path, {{"/tf", MessageType::kTfMessage, messages}});
  const traj::Trajectory t = ReadBagTrajectory(path, {"/tf:odom.b", false});
  ASSERT_EQ(t.size(), 2);
  EXPECT_EQ(t.stamps_ns()[0], s / 4);
  EXPECT_NEAR(t.positions()(0, 0), 10.25, 1e-12);
  EXPECT_NEAR(t.positions()(0, 1), 20.75, 1e-12);
}

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

// `cheval` on recordings end to end: info lists topics, every command takes --topic / --ref-topic /
// --est-topic, several --est-topic evaluate several estimators of one bag, errors exit 1/2/3 with
// the topic or record named and no output file.
#include <cmath>
#include <filesystem>

#include "cheval/bag/bag.h"
#include "cheval/traj/io.h"
#include "../cli/cli_runner.h"

namespace cheval::testing {
namespace {

class BagCli : public CliTest {
 protected:
  // A bag with a ground truth (PoseStamped), two estimates (Odometry with twist, PoseWithCovarianceStamped)
  // and a tf tree, in `container`.
  std::string MakeBag(bag::Container container, const std::string& name) {
    std::vector<bag::PoseMessage> truth, odom, amcl, tf;
    for (int i = 0; i < 200; ++i) {
      bag::PoseMessage m;
      m.stamp_ns = 1000000000LL + i * 50000000LL;  // 20 Hz
      m.record_time_ns = m.stamp_ns + 1000000;
      const double t = 0.05 * i;
      m.position[0] = 2 * std::sin(t);
      m.position[1] = 2 * std::cos(t);
      m.orientation[2] = std::sin(t / 4);
      m.orientation[3] = std::cos(t / 4);
      truth.push_back(m);
      bag::PoseMessage e = m;
      e.position[0] += 0.01 * std::sin(7 * t);
      e.linear[0] = 2.0;
      odom.push_back(e);
      e.position[1] += 0.02;
      amcl.push_back(e);
      e.frame_id = "odom";
      e.child_frame_id = "base";
      tf.push_back(e);
    }
    bag::WriteOptions options;
    options.container = container;
    const std::string path = Path(name);
    bag::WriteBag(path,
                  {{"/truth", bag::MessageType::kPoseStamped, truth},
                   {"/odom", bag::MessageType::kOdometry, odom},
                   {"/amcl", bag::MessageType::kPoseWithCovarianceStamped, amcl},
                   {"/tf", bag::MessageType::kTfMessage, tf}},
                  options);
    return path;
  }
};

TEST_F(BagCli, InfoListsTopicsAndSummarisesOne) {
  const std::string bag = MakeBag(bag::Container::kRos1, "run.bag");
  RunResult r = Cheval("info " + bag);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(ros1 recording, 4 topics)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  /odom        200  nav_msgs/Odometry (ros1)\n"), std::string::npos) << r.out;
  r = Cheval("info " + bag + " --topic /odom");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(ros1 recording, topic /odom)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("poses                 200"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("velocity              yes (world frame)"), std::string::npos) << r.out;
}

TEST_F(BagCli, ApeWithSeveralEstimateTopicsOfOneBag) {
  for (const auto& [container, name] : {std::pair{bag::Container::kRos1, "run.bag"}, std::pair{bag::Container::kMcap, "run.mcap"},
                                        std::pair{bag::Container::kRos2, "run_ros2"}}) {
    const std::string bag = MakeBag(container, name);
    const RunResult r = Cheval("ape " + bag + " " + bag + " --ref-topic /truth --est-topic /odom --est-topic /amcl "
                               "--est-topic /tf:odom.base --json " + Path("ape.json"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(bag + ":/odom: found 200 of max. 200"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(bag + ":/amcl"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(bag + ":/tf:odom.base"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("3 estimates"), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(Path("ape.json")));
    std::filesystem::remove(Path("ape.json"));
  }
}

TEST_F(BagCli, ConvertWritesTheTopicsPoses) {
  const std::string bag = MakeBag(bag::Container::kMcap, "run.mcap");
  const RunResult r = Cheval("convert " + bag + " --topic /odom --to tumv -o " + Path("odom.tum"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const traj::Trajectory from_file = traj::ReadTrajectory(Path("odom.tum"));
  bag::BagReadOptions options;
  options.topic = "/odom";
  const traj::Trajectory from_bag = bag::ReadBagTrajectory(bag, options);
  EXPECT_EQ(from_file.raw_positions(), from_bag.raw_positions());
  EXPECT_EQ(from_file.raw_velocities(), from_bag.raw_velocities());
  // --bag-time: the record times, 1 ms after the stamps.
  ASSERT_EQ(Cheval("convert " + bag + " --topic /odom --bag-time -o " + Path("t.tum")).exit_code, 0);
  EXPECT_EQ(traj::ReadTrajectory(Path("t.tum")).stamps_ns()[0], 1001000000LL);
}

TEST_F(BagCli, AseUsesTheOdometryTwist) {
  const std::string bag = MakeBag(bag::Container::kRos2, "run_ros2");
  const RunResult r = Cheval("ase " + bag + " " + bag + " --ref-topic /truth --est-topic /odom");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("velocity"), std::string::npos) << r.out;
}

TEST_F(BagCli, ErrorsNameTheTopicAndLeaveNoOutput) {
  const std::string bag = MakeBag(bag::Container::kRos1, "run.bag");
  RunResult r = Cheval("ape " + bag + " " + bag + " --ref-topic /truth --est-topic /nope --json " + Path("a.json"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(bag + ":0:0: error: no topic '/nope' in the recording; its topics: /amcl"), std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(Path("a.json")));
  r = Cheval("ape " + bag + " " + bag + " --ref-topic /truth --est-topic /tf:odom.camera");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("tf chain /tf:odom.camera is broken"), std::string::npos) << r.err;
  r = Cheval("info " + bag + " --topic /tf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("topic '/tf' holds tf2_msgs/TFMessage messages, not a trajectory"), std::string::npos) << r.err;
  r = Cheval("convert " + bag + " -o " + Path("x.tum"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("choose a topic with --topic; its topics: /amcl"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(Path("x.tum")));
  r = Cheval("convert " + bag + " --topic /truth --topic /odom -o " + Path("x.tum"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--topic given 2 times"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace cheval::testing

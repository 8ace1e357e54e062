// Broken recordings and wrong requests: each gives InputError (or ComputeError for a tf chain) naming
// the record or the topic, never a crash or a partial trajectory.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cheval/bag/bag.h"
#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "../support/test_data.h"

namespace cheval::bag {
namespace {

class BadBag : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::FreshTestDir("cheval_bad_bag_");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  static std::vector<PoseMessage> Poses(int n) {
    std::vector<PoseMessage> out(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      out[static_cast<size_t>(i)].stamp_ns = out[static_cast<size_t>(i)].record_time_ns = 1000000000LL * (i + 1);
      out[static_cast<size_t>(i)].position[0] = i;
    }
    return out;
  }

  // A recording of one PoseStamped topic "/pose", as bytes.
  std::string Bytes(Container container, const std::string& compression, int n = 30) {
    const std::string path = Path("source");
    WriteOptions options;
    options.container = container;
    options.compression = compression;
    options.messages_per_chunk = 10;
    WriteBag(path, {{"/pose", MessageType::kPoseStamped, Poses(n)}}, options);
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  std::string Save(const std::string& bytes, const std::string& name = "bad.bag") {
    const std::string path = Path(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  // The InputError message of reading /pose from `path`; fails the test if there is none.
  static std::string InputErrorOf(const std::string& path, const std::string& topic = "/pose") {
    try {
      ReadBagTrajectory(path, {topic, false});
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), path);
      return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
  }

  std::filesystem::path dir_;
};

TEST_F(BadBag, TruncatedRos1BagNamesTheRecord) {
  for (const char* compression : {"none", "bz2", "lz4"}) {
    const std::string bytes = Bytes(Container::kRos1, compression);
    for (size_t cut : {bytes.size() - 3, bytes.size() / 2, size_t{4200}, size_t{20}}) {
      const std::string message = InputErrorOf(Save(bytes.substr(0, cut)));
      EXPECT_NE(message.find(" error: "), std::string::npos) << message;
      EXPECT_NE(message.find("record"), std::string::npos) << compression << " cut at " << cut << ": " << message;
    }
  }
}

TEST_F(BadBag, CorruptCompressedChunkIsNamed) {
  for (const char* compression : {"bz2", "lz4"}) {
    std::string bytes = Bytes(Container::kRos1, compression);
    // The first chunk's data starts shortly after the 4096-byte bag header record + header fields.
    for (size_t i = 4096 + 13 + 80; i < 4096 + 13 + 120; ++i) bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
    const std::string message = InputErrorOf(Save(bytes));
    EXPECT_NE(message.find("chunk record at byte 4109"), std::string::npos) << message;
  }
}

TEST_F(BadBag, UnknownCompressionIsNamed) {
  std::string bytes = Bytes(Container::kRos1, "lz4");
  const size_t at = bytes.find("compression=lz4");
  ASSERT_NE(at, std::string::npos);
  bytes.replace(at + 12, 3, "xyz");
  const std::string message = InputErrorOf(Save(bytes));
  EXPECT_NE(message.find("unknown compression 'xyz'"), std::string::npos) << message;
  EXPECT_NE(message.find("chunk record at byte"), std::string::npos) << message;
}

TEST_F(BadBag, IndexThatDisagreesWithItsChunk) {
  std::string bytes = Bytes(Container::kRos1, "none");
  // The first index data record says 10 messages; make it 11.
  const size_t at = bytes.find(std::string("count=\x0a\x00\x00\x00", 10));
  ASSERT_NE(at, std::string::npos);
  bytes[at + 6] = 11;
  const std::string message = InputErrorOf(Save(bytes));
  EXPECT_NE(message.find("index data record at byte"), std::string::npos) << message;
  EXPECT_NE(message.find("holds 11 messages"), std::string::npos) << message;
}

TEST_F(BadBag, McapTruncatedWrongCrcAndUnknownCompression) {
  const std::string bytes = Bytes(Container::kMcap, "zstd");
  EXPECT_NE(InputErrorOf(Save(bytes.substr(0, bytes.size() - 40), "a.mcap")).find("record at byte"), std::string::npos);
  std::string unknown = bytes;
  unknown.replace(unknown.find("zstd"), 4, "brot");
  EXPECT_NE(InputErrorOf(Save(unknown, "b.mcap")).find("unknown compression 'brot'"), std::string::npos);
  // An uncompressed chunk with a CRC that does not match its records.
  std::string crc = Bytes(Container::kMcap, "none");
  const size_t chunk = crc.find('\x06', 8 + 9 + 20);  // after the header record
  ASSERT_NE(chunk, std::string::npos);
  // Set the CRC field (opcode, length u64, 3 x u64, then u32 CRC) to a wrong non-zero value.
  crc[chunk + 9 + 24] = 1;
  const std::string message = InputErrorOf(Save(crc, "c.mcap"));
  EXPECT_NE(message.find("wrong CRC-32"), std::string::npos) << message;
}

TEST_F(BadBag, MissingTopicListsTheTopics) {
  const std::string path = Save(Bytes(Container::kRos1, "none"));
  const std::string message = InputErrorOf(path, "/odom");
  EXPECT_NE(message.find("no topic '/odom'"), std::string::npos) << message;
  EXPECT_NE(message.find("/pose (geometry_msgs/PoseStamped)"), std::string::npos) << message;
}

TEST_F(BadBag, TopicOfAnotherTypeIsRefused) {
  PoseMessage m;
  m.frame_id = "odom";
  const std::string path = Path("tf.bag");
  WriteBag(path, {{"/tf", MessageType::kTfMessage, {m}}});
  const std::string message = InputErrorOf(path, "/tf");
  EXPECT_NE(message.find("topic '/tf' holds tf2_msgs/TFMessage messages, not a trajectory"), std::string::npos)
      << message;
  // And a tf chain on a pose topic.
  const std::string poses = Save(Bytes(Container::kRos1, "none"));
  EXPECT_NE(InputErrorOf(poses, "/pose:a.b").find("a tf chain needs tf2_msgs/TFMessage"), std::string::npos);
}

TEST_F(BadBag, BrokenTfChainIsAComputeError) {
  PoseMessage a, b;
  a.frame_id = "odom", a.child_frame_id = "base";
  b.frame_id = "map", b.child_frame_id = "camera";
  const std::string path = Path("tf.bag");
  WriteBag(path, {{"/tf", MessageType::kTfMessage, {a, b}}});
  try {
    ReadBagTrajectory(path, {"/tf:odom.camera", false});
    FAIL() << "no error";
  } catch (const ComputeError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": tf chain /tf:odom.camera is broken"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ReadBagTrajectory(path, {"/tf:odom", false}), UsageError);
}

TEST_F(BadBag, RecordingWithoutTopicAndTopicForATextFile) {
  const std::string path = Save(Bytes(Container::kRos1, "none"));
  try {
    traj::ReadTrajectory(path);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("ReadOptions::topic; its topics: /pose (geometry_msgs/PoseStamped, 30)"),
              std::string::npos)
        << e.what();
  }
  const std::string text = Save("0 0 0 0 0 0 0 1\n", "a.tum");
  traj::ReadOptions options;
  options.topic = "/pose";
  EXPECT_THROW(traj::ReadTrajectory(text, options), UsageError);
  EXPECT_NO_THROW(traj::ReadTrajectory(text));
}

TEST_F(BadBag, Ros2FolderWithMissingDatabaseOrCompression) {
  const std::string folder = Path("ros2");
  WriteOptions options;
  options.container = Container::kRos2;
  WriteBag(folder, {{"/pose", MessageType::kPoseStamped, Poses(3)}}, options);
  EXPECT_EQ(ReadBagTrajectory(folder, {"/pose", false}).size(), 3);
  std::string yaml;
  {
    std::ifstream in(folder + "/metadata.yaml");
    yaml.assign(std::istreambuf_iterator<char>(in), {});
  }
  // An unknown compression format, zstd without a mode, and zstd FILE over a plain database.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"compression_format: lz4", "metadata.yaml:0:0: error: compression_format 'lz4': only zstd"},
      {"compression_format: zstd", "metadata.yaml:0:0: error: compression_mode '': expected FILE or MESSAGE"},
      {"compression_format: zstd\n  compression_mode: FILE\n  x: ''", "ros2_0.db3:0:0: error: the file (compression_mode "
                                                                      "FILE): not zstd data"}};
  for (const auto& [replacement, expected] : cases) {
    std::string compressed = yaml;
    compressed.replace(compressed.find("compression_format: ''"), 22, replacement);
    compressed.replace(compressed.find("compression_mode: ''"), 20, "");
    std::ofstream(folder + "/metadata.yaml") << compressed;
    try {
      ReadBagTrajectory(folder, {"/pose", false});
      ADD_FAILURE() << "no error for " << replacement;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  std::ofstream(folder + "/metadata.yaml") << yaml;
  std::filesystem::remove(folder + "/ros2_0.db3");
  EXPECT_THROW(ReadBagTrajectory(folder, {"/pose", false}), InputError);
}

TEST_F(BadBag, OtherRosbagVersionIsNamed) {
  const std::string path = Save("#ROSBAG V1.2\nwhatever");
  EXPECT_EQ(DetectContainer(path), Container::kRos1);
  EXPECT_NE(InputErrorOf(path).find("ROS 1 bag version 1.2"), std::string::npos);
}

TEST_F(BadBag, CorruptZstdInCompressedRos2FoldersIsNamed) {
  for (const char* mode : {"file", "message"}) {
    const std::string folder = Path(std::string("ros2_") + mode);
    WriteOptions options;
    options.container = Container::kRos2;
    options.compression = "zstd";
    options.ros2_compression_mode = mode;
    WriteBag(folder, {{"/pose", MessageType::kPoseStamped, Poses(5)}}, options);
    ASSERT_EQ(ReadBagTrajectory(folder, {"/pose", false}).size(), 5) << mode;
    const std::string db = folder + "/ros2_" + mode + "_0.db3" + (std::string(mode) == "file" ? ".zstd" : "");
    std::string bytes;
    {
      std::ifstream in(db, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    if (std::string(mode) == "file") {
      bytes.resize(bytes.size() / 2);  // a truncated frame
    } else {
      // The first message's zstd frame magic (28 B5 2F FD) broken.
      const size_t magic = bytes.find("\x28\xb5\x2f\xfd");
      ASSERT_NE(magic, std::string::npos);
      bytes[magic + 1] = 'x';
    }
    std::ofstream(db, std::ios::binary | std::ios::trunc) << bytes;
    // The error names the compressed database (FILE) or the database and the message (MESSAGE).
    try {
      ReadBagTrajectory(folder, {"/pose", false});
      ADD_FAILURE() << "no error for " << mode;
    } catch (const InputError& e) {
      const std::string message = e.what();
      const std::string expected = std::string(mode) == "file"
                                       ? db + ":0:0: error: the file (compression_mode FILE): zstd data does not "
                                              "decompress"
                                       : db + ":0:0: error: message ";
      EXPECT_EQ(message.find(expected), 0u) << message;
      if (std::string(mode) == "message") {
        EXPECT_NE(message.find("(compression_mode MESSAGE, log time "), std::string::npos) << message;
        EXPECT_NE(message.find("not zstd data"), std::string::npos) << message;
      }
    }
  }
}

}  // namespace
}  // namespace cheval::bag

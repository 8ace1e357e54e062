#pragma once
/// \file
/// Trajectories straight from robot recordings (docs/bags.md): ROS 1 bags (v2.0; chunks uncompressed,
/// bz2 or lz4), ROS 2 bag folders (metadata.yaml + sqlite3 .db3, or .mcap files; CDR) and MCAP files
/// (chunks uncompressed, zstd or lz4; CDR or ROS 1 encoding).
///
/// A topic becomes a traj::Trajectory from one of these message types:
///
/// | Type                                   | Pose                  | Velocity                          |
/// |----------------------------------------|-----------------------|-----------------------------------|
/// | geometry_msgs/PoseStamped              | pose                  | -                                 |
/// | geometry_msgs/PoseWithCovarianceStamped| pose.pose             | -                                 |
/// | geometry_msgs/TransformStamped         | transform             | -                                 |
/// | nav_msgs/Odometry                      | pose.pose             | R · twist.linear (world), twist.angular (body) |
/// | nav_msgs/Path                          | the last message's poses | -                              |
/// | tf2_msgs/TFMessage (`/tf:parent.child`)| the chain parent → child | -                              |
///
/// Stamps are the message header's (evo's default) or, with `record_time`, the time the recorder
/// logged the message. Poses are in record-time order (as evo reads them); stamps are kept as read.
/// Every problem throws InputError `PATH: error: ...` naming the record or the topic (exit 2), or
/// ComputeError for a tf chain that cannot be looked up (exit 3).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cheval/traj/trajectory.h"

namespace cheval::bag {

/// The recording containers.
enum class Container {
  kNone,  ///< not a recording (a text trajectory file, or missing)
  kRos1,  ///< ROS 1 bag v2.0, magic `#ROSBAG V2.0\n`
  kRos2,  ///< a ROS 2 bag folder: a directory with metadata.yaml
  kMcap,  ///< an MCAP file, magic `\x89MCAP0\r\n`
};

/// Name of a container ("ros1", "ros2", "mcap"; "none").
const char* ToString(Container container);

/// The container at `path` by its magic bytes (a directory by its metadata.yaml); kNone for anything
/// else, including a missing file (the text readers then report it). Never throws.
Container DetectContainer(const std::string& path);

/// One topic of a recording.
struct TopicInfo {
  std::string name;
  std::string type;      ///< as recorded, e.g. "geometry_msgs/PoseStamped" or "nav_msgs/msg/Odometry"
  std::string encoding;  ///< "ros1" or "cdr"
  int64_t count = 0;     ///< messages on the topic
};

/// The topics of a recording, sorted by name. InputError for a broken recording.
std::vector<TopicInfo> ListTopics(const std::string& path);

/// What to read from a recording.
struct BagReadOptions {
  /// The topic; a TFMessage chain as `/tf:PARENT.CHILD` (frames from /tf and /tf_static).
  std::string topic;
  /// Stamps from the recorder's log time instead of the message header.
  bool record_time = false;

  /// UsageError-style OptionError when `topic` is empty.
  void Validate() const;
};

/// Reads the trajectory on `options.topic`. InputError naming the topic when it is missing (listing
/// the topics there are), of a type that is not a trajectory, or when a message does not decode;
/// ComputeError when a tf chain cannot be looked up at any stamp.
traj::Trajectory ReadBagTrajectory(const std::string& path, const BagReadOptions& options);

/// The hook of traj::ReadTrajectory: the trajectory on `topic` when `path` is a recording; nullopt
/// for any other path when `topic` is empty. UsageError when a recording has no `topic` (listing its
/// topics) or `topic` is given for a file that is not a recording.
std::optional<traj::Trajectory> ReadIfRecording(const std::string& path, const std::string& topic, bool record_time);

/// A message to write (tests and benchmarks write recordings with this).
struct PoseMessage {
  int64_t stamp_ns = 0;        ///< header stamp
  int64_t record_time_ns = 0;  ///< log time
  std::string frame_id = "world";
  std::string child_frame_id = "body";  ///< Odometry and TransformStamped
  double position[3] = {0, 0, 0};
  double orientation[4] = {0, 0, 0, 1};  ///< x y z w
  double linear[3] = {0, 0, 0};          ///< Odometry: twist.linear in the child frame
  double angular[3] = {0, 0, 0};         ///< Odometry: twist.angular in the child frame
};

/// The message types the writer writes (one per topic).
enum class MessageType { kPoseStamped, kPoseWithCovarianceStamped, kTransformStamped, kOdometry, kPath, kTfMessage };

/// One topic to write. kPath writes one Path message per element of `messages` holding all poses up to
/// it; kTfMessage one TFMessage per message (one transform each).
struct TopicToWrite {
  std::string name;
  MessageType type = MessageType::kPoseStamped;
  std::vector<PoseMessage> messages;
};

/// How to write a recording.
struct WriteOptions {
  Container container = Container::kRos1;
  /// Compression of the chunks: "none", "bz2" or "lz4" (ROS 1), "none", "zstd" or "lz4" (MCAP); of a
  /// ROS 2 folder: "none" or "zstd" (see `ros2_compression_mode`).
  std::string compression = "none";
  /// ROS 2 with "zstd": "file" (the .db3 stored as .db3.zstd) or "message" (each message compressed).
  std::string ros2_compression_mode = "file";
  /// MCAP only: "cdr" or "ros1" message encoding.
  std::string mcap_encoding = "cdr";
  /// Messages per chunk (ROS 1, MCAP).
  int64_t messages_per_chunk = 1000;
};

/// Writes a recording of `topics` to `path` (a file; a folder for ROS 2, created). Messages are
/// written in record-time order. Throws OutputError.
void WriteBag(const std::string& path, const std::vector<TopicToWrite>& topics, const WriteOptions& options = {});

}  // namespace cheval::bag

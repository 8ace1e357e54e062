// Message decoding (ROS 1 serialization and CDR) of the trajectory types, and the trajectory of a
// topic: poses, Odometry twists, the last Path, tf chains.
#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "cheval/bag/bag.h"
#include "container.h"
#include "message_reader.h"
#include "tf.h"

namespace cheval::bag {
namespace {

constexpr std::string_view kMcapMagic("\x89MCAP0\r\n", 8);

}  // namespace

const char* ToString(Container container) {
  switch (container) {
    case Container::kRos1: return "ros1";
    case Container::kRos2: return "ros2";
    case Container::kMcap: return "mcap";
    case Container::kNone: break;
  }
  return "none";
}

Container DetectContainer(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    return std::filesystem::is_regular_file(std::filesystem::path(path) / "metadata.yaml", error) ? Container::kRos2
                                                                                                   : Container::kNone;
  }
  // Only a regular file can be a recording (the readers seek). A FIFO, a device or standard input is
  // never opened here: a second open by the trajectory reader would find its writer gone.
  if (!std::filesystem::is_regular_file(path, error)) return Container::kNone;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return Container::kNone;
  char head[13] = {};
  const size_t n = std::fread(head, 1, sizeof(head), file);
  std::fclose(file);
  const std::string_view bytes(head, n);
  if (bytes.substr(0, 9) == "#ROSBAG V") return Container::kRos1;  // other versions: the reader names them
  if (bytes.substr(0, kMcapMagic.size()) == kMcapMagic) return Container::kMcap;
  return Container::kNone;
}

std::string ShortType(std::string_view type) {
  // ROS 2 spells "pkg/msg/Name"; ROS 1 "pkg/Name".
  const size_t msg = type.find("/msg/");
  if (msg == std::string_view::npos) return std::string(type);
  return std::string(type.substr(0, msg)) + "/" + std::string(type.substr(msg + 5));
}

namespace {

void Walk(const std::string& path, Container container, const Visitor& visitor) {
  switch (container) {
    case Container::kRos1: ReadRos1(path, visitor); return;
    case Container::kMcap: ReadMcap(path, visitor); return;
    case Container::kRos2: ReadRos2(path, visitor); return;
    case Container::kNone: break;
  }
  throw InputError(path, 0, 0, "not a recording: expected a ROS 1 bag, an MCAP file or a ROS 2 bag folder");
}

Container RequireContainer(const std::string& path) {
  const Container container = DetectContainer(path);
  if (container == Container::kNone) Walk(path, container, {});
  return container;
}

enum class Kind { kPoseStamped, kPoseWithCovarianceStamped, kTransformStamped, kOdometry, kPath, kTfMessage, kOther };

Kind KindOf(std::string_view type) {
  const std::string t = ShortType(type);
  if (t == "geometry_msgs/PoseStamped") return Kind::kPoseStamped;
  if (t == "geometry_msgs/PoseWithCovarianceStamped") return Kind::kPoseWithCovarianceStamped;
  if (t == "geometry_msgs/TransformStamped") return Kind::kTransformStamped;
  if (t == "nav_msgs/Odometry") return Kind::kOdometry;
  if (t == "nav_msgs/Path") return Kind::kPath;
  if (t == "tf2_msgs/TFMessage") return Kind::kTfMessage;
  return Kind::kOther;
}

// One decoded pose.
struct Sample {
  int64_t log_time_ns = 0;
  int64_t stamp_ns = 0;
  double position[3];
  double orientation[4];
  double linear[3];
  double angular[3];
};

void ReadPose(MessageReader& reader, Sample* s) {
  reader.F64s(s->position, 3);
  reader.F64s(s->orientation, 4);
}

// Decodes one message of a pose type into `out` (Path: all its poses).
void Decode(Kind kind, MessageReader& reader, int64_t log_time_ns, std::vector<Sample>* out) {
  std::string_view frame;
  Sample s;
  s.log_time_ns = log_time_ns;
  switch (kind) {
    case Kind::kPoseStamped:
      s.stamp_ns = reader.Header(&frame);
      ReadPose(reader, &s);
      break;
    case Kind::kPoseWithCovarianceStamped:
      s.stamp_ns = reader.Header(&frame);
      ReadPose(reader, &s);
      reader.SkipF64s(36);
      break;
    case Kind::kTransformStamped:
      s.stamp_ns = reader.Header(&frame);
      reader.String();  // child_frame_id
      ReadPose(reader, &s);
      break;
    case Kind::kOdometry:
      s.stamp_ns = reader.Header(&frame);
      reader.String();  // child_frame_id
      ReadPose(reader, &s);
      reader.SkipF64s(36);
      reader.F64s(s.linear, 3);
      reader.F64s(s.angular, 3);
      reader.SkipF64s(36);
      break;
    case Kind::kPath: {
      reader.Header(&frame);
      const uint32_t n = reader.U32();
      out->clear();  // the last message wins
      for (uint32_t i = 0; i < n; ++i) {
        Sample p;
        p.log_time_ns = log_time_ns;
        p.stamp_ns = reader.Header(&frame);
        ReadPose(reader, &p);
        out->push_back(p);
      }
      return;
    }
    case Kind::kTfMessage:
    case Kind::kOther: return;
  }
  out->push_back(s);
}

std::string TypeList() {
  return "geometry_msgs/PoseStamped, PoseWithCovarianceStamped, TransformStamped, nav_msgs/Odometry, nav_msgs/Path, "
         "or /tf:PARENT.CHILD for tf2_msgs/TFMessage";
}

[[noreturn]] void MissingTopic(const std::string& path, const std::string& topic, const std::vector<TopicInfo>& topics) {
  std::string list;
  for (const TopicInfo& t : topics) list += fmt::format("{}{} ({})", list.empty() ? "" : ", ", t.name, t.type);
  throw InputError(path, 0, 0, fmt::format("no topic '{}' in the recording; its topics: {}", topic,
                                           list.empty() ? "none" : list));
}

}  // namespace

std::vector<TopicInfo> ListTopics(const std::string& path) {
  const Container container = RequireContainer(path);
  return ListTopicsWith([&](const Visitor& visitor) { Walk(path, container, visitor); });
}

std::vector<TopicInfo> ListTopicsWith(const Walker& walk) {
  std::map<uint64_t, size_t> index;  // connection -> topic slot
  std::vector<TopicInfo> topics;
  Visitor visitor;
  visitor.on_connection = [&](uint64_t id, const Connection& c) {
    size_t slot = topics.size();
    for (size_t i = 0; i < topics.size(); ++i) {
      if (topics[i].name == c.topic && topics[i].type == c.type) slot = i;
    }
    if (slot == topics.size()) topics.push_back({c.topic, c.type, c.encoding == Encoding::kCdr ? "cdr" : c.encoding == Encoding::kRos1 ? "ros1" : "other", 0});
    index[id] = slot;
    return true;
  };
  visitor.on_message = [&](uint64_t id, int64_t, std::string_view) { ++topics[index[id]].count; };
  walk(visitor);
  std::sort(topics.begin(), topics.end(), [](const TopicInfo& a, const TopicInfo& b) {
    return a.name != b.name ? a.name < b.name : a.type < b.type;
  });
  return topics;
}

void BagReadOptions::Validate() const {
  if (topic.empty()) throw OptionError("BagReadOptions", "topic", "must name the topic to read from a recording");
}

traj::Trajectory ReadBagTrajectory(const std::string& path, const BagReadOptions& options) {
  const Container container = RequireContainer(path);
  return ReadTrajectoryWith(path, [&](const Visitor& visitor) { Walk(path, container, visitor); }, options);
}

traj::Trajectory ReadTrajectoryWith(const std::string& path, const Walker& walk, const BagReadOptions& options) {
  options.Validate();
  const std::optional<TfChain> chain = ParseTfTopic(options.topic);
  if (chain) return ReadTfTrajectory(path, *chain, options.record_time, walk);

  std::map<uint64_t, Kind> wanted;
  std::vector<TopicInfo> seen;
  std::string type_found;
  std::vector<Sample> samples;
  Visitor visitor;
  std::map<uint64_t, Encoding> encodings;
  visitor.on_connection = [&](uint64_t id, const Connection& c) {
    seen.push_back({c.topic, c.type, "", 0});
    if (c.topic != options.topic) return false;
    const Kind kind = KindOf(c.type);
    if (kind == Kind::kOther || kind == Kind::kTfMessage) {
      throw InputError(path, 0, 0, fmt::format("topic '{}' holds {} messages, not a trajectory; expected {}",
                                               options.topic, c.type, TypeList()));
    }
    if (!type_found.empty() && ShortType(type_found) != ShortType(c.type)) {
      throw InputError(path, 0, 0, fmt::format("topic '{}' holds both {} and {} messages", options.topic, type_found,
                                               c.type));
    }
    type_found = c.type;
    wanted[id] = kind;
    encodings[id] = c.encoding;
    return true;
  };
  int64_t count = 0;
  std::string prefix;  // "topic 'NAME' (TYPE) "
  visitor.on_message = [&](uint64_t id, int64_t log_time_ns, std::string_view data) {
    if (++count == 1) prefix = fmt::format("topic '{}' ({}) ", options.topic, type_found);
    MessageReader reader(data, encodings[id], path, prefix, count);
    Decode(wanted[id], reader, log_time_ns, &samples);
  };
  walk(visitor);
  if (wanted.empty()) {
    std::sort(seen.begin(), seen.end(), [](const TopicInfo& a, const TopicInfo& b) { return a.name < b.name; });
    seen.erase(std::unique(seen.begin(), seen.end(), [](const TopicInfo& a, const TopicInfo& b) {
                 return a.name == b.name && a.type == b.type;
               }), seen.end());
    MissingTopic(path, options.topic, seen);
  }
  if (samples.empty()) {
    throw InputError(path, 0, 0, fmt::format("topic '{}' has no poses ({} messages of {})", options.topic, count,
                                             type_found));
  }
  const Kind kind = wanted.begin()->second;
  // Record-time order, as evo reads (a Path's poses keep their order).
  const auto by_log_time = [](const Sample& a, const Sample& b) { return a.log_time_ns < b.log_time_ns; };
  if (kind != Kind::kPath && !std::is_sorted(samples.begin(), samples.end(), by_log_time)) {
    std::stable_sort(samples.begin(), samples.end(), by_log_time);
  }
  traj::Channels channels;
  channels.velocity = channels.angular_velocity = kind == Kind::kOdometry;
  traj::Trajectory trajectory(channels);
  trajectory.Reserve(static_cast<Eigen::Index>(samples.size()));
  for (const Sample& s : samples) {
    const double* q = s.orientation;
    const double n = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!(n > 8.881784197001252e-16) || !std::isfinite(n) || !std::isfinite(s.position[0] + s.position[1] + s.position[2])) {
      throw InputError(path, 0, 0, fmt::format("topic '{}': the pose at stamp {} ns has a {}", options.topic, s.stamp_ns,
                                               std::isfinite(n) && n <= 8.881784197001252e-16
                                                   ? "zero quaternion"
                                                   : "non-finite value"));
    }
    double velocity[3] = {0, 0, 0};
    if (kind == Kind::kOdometry) {
      // Odometry's twist is in child_frame_id (the body): v_world = R_world_body · v_body.
      const Eigen::Vector3d v = traj::RotationFromQuaternion(q[0], q[1], q[2], q[3]) *
                                Eigen::Vector3d(s.linear[0], s.linear[1], s.linear[2]);
      if (!v.allFinite() || !std::isfinite(s.angular[0] + s.angular[1] + s.angular[2])) {
        throw InputError(path, 0, 0, fmt::format("topic '{}': the twist at stamp {} ns has a non-finite value",
                                                 options.topic, s.stamp_ns));
      }
      velocity[0] = v.x(), velocity[1] = v.y(), velocity[2] = v.z();
    }
    const int64_t stamp = options.record_time && kind != Kind::kPath ? s.log_time_ns : s.stamp_ns;
    trajectory.Append(stamp, s.position, s.orientation, velocity, s.angular);
  }
  return trajectory;
}

std::optional<traj::Trajectory> ReadIfRecording(const std::string& path, const std::string& topic, bool record_time) {
  const Container container = DetectContainer(path);
  if (container == Container::kNone) {
    if (topic.empty()) return std::nullopt;
    throw UsageError(fmt::format("ReadOptions::topic '{}' is for recordings (ROS 1 bag, ROS 2 bag folder, MCAP); {} "
                                 "is not one",
                                 topic, path));
  }
  if (topic.empty()) {
    std::string list;
    for (const TopicInfo& t : ListTopics(path)) list += fmt::format("{}{} ({}, {})", list.empty() ? "" : ", ", t.name, t.type, t.count);
    throw UsageError(fmt::format("{} is a {} recording: choose a topic with ReadOptions::topic; its topics: {}", path,
                                 container == Container::kRos1 ? "ROS 1 bag" : container == Container::kRos2 ? "ROS 2 bag" : "MCAP",
                                 list.empty() ? "none" : list));
  }
  return ReadBagTrajectory(path, {topic, record_time});
}

}  // namespace cheval::bag

#include "bag_fuzzer_checks.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "../src/bag/container.h"
#include "cheval/bag/bag.h"
#include "cheval/common/error.h"

namespace cheval::fuzz {
namespace {

std::optional<std::string> CheckTrajectory(const traj::Trajectory& t, bool odometry, const std::string& what) {
  if (t.empty()) return what + ": no poses";
  const traj::TrajectoryView v = t.View();
  if (v.has_velocity() != odometry || v.has_angular_velocity() != odometry) return what + ": velocity channels";
  const Eigen::Index n = t.size();
  if (static_cast<Eigen::Index>(t.raw_positions().size()) != 3 * n ||
      static_cast<Eigen::Index>(t.raw_orientations().size()) != 4 * n ||
      (odometry && static_cast<Eigen::Index>(t.raw_velocities().size()) != 3 * n)) {
    return what + ": channel sizes";
  }
  if (!v.positions().allFinite() || !v.quaternions().allFinite()) return what + ": a non-finite pose";
  if ((v.quaternions().colwise().squaredNorm().array() <= 0).any()) return what + ": a zero quaternion";
  if (odometry && (!v.velocities().allFinite() || !v.angular_velocities().allFinite())) {
    return what + ": a non-finite velocity";
  }
  return std::nullopt;
}

// Runs `step`; an InputError must name `path` first, a ComputeError is accepted when `compute_ok`.
template <typename Step>
std::optional<std::string> Guarded(const std::string& path, bool compute_ok, const std::string& what, Step step) {
  try {
    return step();
  } catch (const InputError& e) {
    if (std::string_view(e.what()).substr(0, path.size()) != path) {
      return fmt::format("{}: InputError not naming the path: {}", what, e.what());
    }
  } catch (const ComputeError& e) {
    if (!compute_ok) return fmt::format("{}: ComputeError: {}", what, e.what());
  } catch (const Error& e) {
    return fmt::format("{}: unexpected cheval::Error: {}", what, e.what());
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> CheckBagInput(std::string_view container, std::string_view data) {
  std::string path;
  bag::Walker walk;
  std::filesystem::path folder;
  if (container == "ros1") {
    path = "fuzz.bag";
    walk = [&](const bag::Visitor& v) { bag::ReadRos1Bytes(data, path, v); };
  } else if (container == "mcap") {
    path = "fuzz.mcap";
    walk = [&](const bag::Visitor& v) { bag::ReadMcapBytes(data, path, v); };
  } else if (container == "ros2" || container == "ros2_file" || container == "ros2_message") {
    // ros2_file: the input is a zstd-compressed database (compression_mode FILE); ros2_message: a
    // database whose messages are zstd frames (MESSAGE).
    folder = std::filesystem::temp_directory_path() / fmt::format("cheval_fuzz_{}_{}", container, ::getpid());
    std::filesystem::create_directories(folder);
    const std::string file = container == "ros2_file" ? "fuzz.db3.zstd" : "fuzz.db3";
    const std::string compression = container == "ros2" ? "''" : "zstd";
    const std::string mode = container == "ros2" ? "''" : container == "ros2_file" ? "FILE" : "MESSAGE";
    std::ofstream(folder / file, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
    std::ofstream(folder / "metadata.yaml") << "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n"
                                               "  compression_format: " << compression << "\n  compression_mode: "
                                            << mode << "\n  relative_file_paths:\n  - " << file << "\n";
    path = folder.string();
    walk = [&](const bag::Visitor& v) { bag::ReadRos2(path, v); };
  } else {
    throw std::invalid_argument("unknown bag fuzz target " + std::string(container));
  }
  std::vector<bag::TopicInfo> topics;
  auto run = [&]() -> std::optional<std::string> {
    if (auto v = Guarded(path, false, "ListTopics", [&]() -> std::optional<std::string> {
          topics = bag::ListTopicsWith(walk);
          return std::nullopt;
        })) {
      return v;
    }
    int read = 0;
    for (const bag::TopicInfo& topic : topics) {
      if (topic.name.empty() || topic.name.find(':') != std::string::npos || ++read > 8) continue;
      const std::string type = topic.type;
      const bool tf = type.find("TFMessage") != std::string::npos;
      const bool odometry = type == "nav_msgs/Odometry" || type == "nav_msgs/msg/Odometry";
      const bool pose = odometry || type.find("PoseStamped") != std::string::npos ||
                        type.find("PoseWithCovarianceStamped") != std::string::npos ||
                        type.find("TransformStamped") != std::string::npos || type.find("nav_msgs") != std::string::npos;
      if (!tf && !pose) continue;
      for (const bool record_time : {false, true}) {
        bag::BagReadOptions options;
        options.topic = tf ? topic.name + ":world.body" : topic.name;
        options.record_time = record_time;
        const std::string what = fmt::format("topic '{}'{}", options.topic, record_time ? " (record time)" : "");
        if (auto v = Guarded(path, tf, what, [&]() -> std::optional<std::string> {
              return CheckTrajectory(bag::ReadTrajectoryWith(path, walk, options), odometry, what);
            })) {
          return v;
        }
      }
    }
    return std::nullopt;
  };
  std::optional<std::string> result = run();
  if (!folder.empty()) std::filesystem::remove_all(folder);
  return result;
}

}  // namespace cheval::fuzz

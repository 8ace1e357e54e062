// Reading 1,000,000 PoseStamped messages from a recording against reading the same poses from a TUM
// file, side by side in one run (issue #16 asks for at most 2x). A plain program: it writes the files
// with bag::WriteBag and traj::WriteTrajectory into a temporary folder, times each read (best of 3,
// process CPU time, user + sys, which other processes' load barely changes; and wall clock) with the
// TUM read timed again just before each container, and prints the table with the ratios to TUM.
//
//   bag_bench [POSES]      (default 1000000)
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include <fmt/format.h>

#include "cheval/bag/bag.h"
#include "cheval/traj/io.h"

namespace {

double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

struct Timing {
  double cpu = 1e300, wall = 1e300;
};

Timing BestOf3(const std::function<cheval::traj::Trajectory()>& read, Eigen::Index expected) {
  Timing best;
  for (int run = 0; run < 3; ++run) {
    const double cpu_start = CpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    const cheval::traj::Trajectory t = read();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double cpu = CpuSeconds() - cpu_start;
    if (t.size() != expected) {
      fmt::print(stderr, "read {} poses, expected {}\n", t.size(), expected);
      std::exit(1);
    }
    best.cpu = std::min(best.cpu, cpu);
    best.wall = std::min(best.wall, wall);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace cheval;
  const int n = argc > 1 ? std::atoi(argv[1]) : 1000000;
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / fmt::format("cheval_bag_bench_{}", ::getpid());
  std::filesystem::create_directories(dir);

  bag::TopicToWrite topic{"/pose", bag::MessageType::kPoseStamped, {}};
  topic.messages.reserve(static_cast<size_t>(n));
  traj::Trajectory poses;
  for (int i = 0; i < n; ++i) {
    bag::PoseMessage m;
    m.stamp_ns = 1700000000000000000LL + i * 5000000LL;  // 200 Hz
    m.record_time_ns = m.stamp_ns + 1000;
    const double t = 0.005 * i;
    m.position[0] = 3 * std::sin(0.3 * t) + 1e-3 * std::sin(17.0 * i);
    m.position[1] = 3 * std::cos(0.2 * t);
    m.position[2] = 1.5 + 0.1 * std::sin(t);
    m.orientation[2] = std::sin(0.05 * t);
    m.orientation[3] = std::cos(0.05 * t);
    poses.Append(m.stamp_ns, m.position, m.orientation);
    topic.messages.push_back(m);
  }
  const std::string tum = (dir / "poses.tum").string();
  traj::WriteTrajectory(tum, poses.View(), traj::Format::kTum);

  struct Case {
    const char* name;
    bag::Container container;
    const char* compression;
    std::string path;
  };
  std::vector<Case> cases = {{"ROS 1 bag, uncompressed", bag::Container::kRos1, "none", (dir / "a.bag").string()},
                             {"ROS 1 bag, lz4", bag::Container::kRos1, "lz4", (dir / "b.bag").string()},
                             {"ROS 1 bag, bz2", bag::Container::kRos1, "bz2", (dir / "c.bag").string()},
                             {"MCAP, zstd, CDR", bag::Container::kMcap, "zstd", (dir / "d.mcap").string()},
                             {"MCAP, uncompressed, CDR", bag::Container::kMcap, "none", (dir / "e.mcap").string()},
                             {"ROS 2 folder, sqlite3", bag::Container::kRos2, "none", (dir / "f").string()}};
  for (const Case& c : cases) {
    bag::WriteOptions options;
    options.container = c.container;
    options.compression = c.compression;
    options.messages_per_chunk = 4096;
    bag::WriteBag(c.path, {topic}, options);
  }

  fmt::print("{} PoseStamped, best of 3 reads; CPU seconds (user + sys) and wall seconds, each against the TUM\n"
             "read timed just before it\n", n);
  fmt::print("{:<26} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}\n", "input", "MB", "CPU s", "TUM CPU", "vs TUM", "wall s",
             "vs TUM");
  auto size_mb = [](const std::string& path) {
    std::uintmax_t bytes = 0;
    if (std::filesystem::is_directory(path)) {
      for (const auto& e : std::filesystem::directory_iterator(path)) bytes += e.file_size();
    } else {
      bytes = std::filesystem::file_size(path);
    }
    return static_cast<double>(bytes) / 1e6;
  };
  fmt::print("{:<26} {:>8.1f}\n", "TUM text", size_mb(tum));
  std::vector<double> cpu(cases.size()), tum_cpu(cases.size());
  for (size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    traj::ReadOptions options;
    options.topic = "/pose";
    const Timing text = BestOf3([&] { return traj::ReadTrajectory(tum); }, n);
    const Timing bag = BestOf3([&] { return traj::ReadTrajectory(c.path, options); }, n);
    cpu[k] = bag.cpu;
    tum_cpu[k] = text.cpu;
    fmt::print("{:<26} {:>8.1f} {:>8.3f} {:>8.3f} {:>8.2f} {:>8.3f} {:>8.2f}\n", c.name, size_mb(c.path), bag.cpu,
               text.cpu, bag.cpu / text.cpu, bag.wall, bag.wall / text.wall);
  }
  // The same records read from bz2 chunks and from plain ones: the difference is libbz2's share.
  const double bz2_only = cpu[2] - cpu[0];
  fmt::print("{:<26} {:>8} {:>8.3f} {:>8.3f} {:>8.2f}   (bz2 CPU - uncompressed CPU)\n", "bz2 decompression alone", "",
             bz2_only, tum_cpu[2], bz2_only / tum_cpu[2]);
  std::filesystem::remove_all(dir);
}

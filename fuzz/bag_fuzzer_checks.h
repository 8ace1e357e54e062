#pragma once
/// \file
/// What the recording fuzz targets (fuzz/bag_fuzzer.cc, one per container) run on one input and the
/// properties they check; tests/bag/bag_fuzz_regression_test.cc replays tests/data/fuzz/bag_<container>/
/// through the same function. docs/fuzzing.md lists the properties.
#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace cheval::fuzz {

/// The containers: "ros1" (the bytes are a ROS 1 bag), "mcap" (an MCAP file), "ros2" (the bytes are
/// the sqlite3 database of a ROS 2 folder whose metadata.yaml names it), "ros2_file" (that database
/// zstd-compressed, compression_mode FILE), "ros2_message" (a database of zstd-compressed messages,
/// compression_mode MESSAGE).
inline constexpr std::array<std::string_view, 5> kBagTargets{{"ros1", "mcap", "ros2", "ros2_file", "ros2_message"}};

/// Lists the topics of the recording in `data` and reads every topic of a pose type (header and
/// record time) and, for a TFMessage topic, the chain TOPIC:world.body. Fine: each step gives a
/// trajectory with at least one pose, consistent channel sizes, finite values and non-zero
/// quaternions, velocity channels exactly for Odometry, or throws InputError whose message begins
/// with the path (for ros2 the folder, or a file in it; ComputeError for a tf chain). Returns nullopt or the violated property.
std::optional<std::string> CheckBagInput(std::string_view container, std::string_view data);

}  // namespace cheval::fuzz

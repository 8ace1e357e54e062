#include "common.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string_view>

#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::cli {

void AddInputFlags(CLI::App* command, InputFlags* flags, const std::string& prefix) {
  command
      ->add_option(Flag("ReadOptions::format", prefix), flags->format,
                   "Input format; auto decides by extension and content")
      ->check(CLI::IsMember({"auto", "tum", "tumv", "euroc", "kitti", "vins", "csv"}))
      ->capture_default_str();
  command
      ->add_option(Flag("ReadOptions::columns", prefix), flags->columns,
                   "Column map for --format csv, e.g. t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz (_ skips a column)")
      ->check(CLI::Validator(
          [](const std::string& map) {
            return map.empty() ? std::string("must name the columns (e.g. t,px,py,pz,qx,qy,qz,qw), got an empty map")
                               : std::string();
          },
          ""));
  command->add_option(Flag("ReadOptions::kitti_times_path", prefix), flags->kitti_times,
                      "KITTI: file with one stamp (seconds) per pose");
  command->add_option(Flag("ReadOptions::topic", prefix), flags->topics,
                      "Recordings (ROS 1/2 bag, MCAP): the topic, or /tf:PARENT.CHILD for a tf chain (docs/bags.md)");
  command->add_flag(Flag("ReadOptions::record_time", prefix), flags->bag_time,
                    "Recordings: stamps from the record (log) time instead of the message headers");
}

traj::ReadOptions InputFlags::ToReadOptions() const {
  if (topics.size() > 1) {
    throw UsageError(fmt::format("{} given {} times; only the estimates of ape/rpe/ase/report take several",
                                 Flag("ReadOptions::topic"), topics.size()));
  }
  traj::ReadOptions options = traj::ReadOptions::FromNames(format, columns, kitti_times);
  if (!topics.empty()) options.topic = topics.front();
  options.record_time = bag_time;
  return options;
}

std::vector<int64_t> ReadQueryStamps(const std::string& path) {
  try {
    return traj::ReadStampsFile(path);
  } catch (const InputError& as_stamps) {
    try {
      const traj::Trajectory trajectory = traj::ReadTrajectory(path);
      return {trajectory.stamps_ns().begin(), trajectory.stamps_ns().end()};
    } catch (const InputError&) {
      throw as_stamps;  // report the simpler expectation
    }
  }
}

namespace {

// The text of an integer option: an optional sign and decimal digits within int64 (`is_signed`) or
// uint64. Rewritten without sign or leading zeros, so that CLI11 (strtoll with base 0) cannot read it as
// octal. An error message, empty when the text is good.
std::string CheckInteger(std::string& text, bool is_signed) {
  std::string_view digits = text;
  const bool negative = digits.starts_with('-');
  if (negative || digits.starts_with('+')) digits.remove_prefix(1);
  const bool all_digits = !digits.empty() && digits.find_first_not_of("0123456789") == std::string_view::npos;
  const std::string_view kind = is_signed ? "a whole number" : "a whole number >= 0";
  if (!all_digits) return fmt::format("must be {}, got '{}'", kind, text);
  if (negative && !is_signed) return fmt::format("must be {}, got {}", kind, text);
  std::uint64_t magnitude = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), magnitude);
  const std::uint64_t most = is_signed ? (negative ? std::uint64_t{1} << 63 : (std::uint64_t{1} << 63) - 1)
                                       : ~std::uint64_t{0};
  if (error != std::errc() || end != digits.data() + digits.size() || magnitude > most) {
    return is_signed ? fmt::format("must be a whole number from -9223372036854775808 to 9223372036854775807, got {}", text)
                     : fmt::format("must be a whole number from 0 to 18446744073709551615, got {}", text);
  }
  text = (negative && magnitude != 0 ? "-" : "") + std::to_string(magnitude);
  return "";
}

// The text of a floating-point option: a decimal number whose value is a finite double.
std::string CheckFinite(const std::string& text) {
  std::string_view number = text;
  if (number.size() > 1 && number[0] == '+' && (std::isdigit(static_cast<unsigned char>(number[1])) || number[1] == '.')) {
    number.remove_prefix(1);
  }
  double value = 0;
  const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
  if (error == std::errc::result_out_of_range) return fmt::format("must be a number within the range of a double, got {}", text);
  if (error != std::errc() || end != number.data() + number.size()) return fmt::format("must be a number, got '{}'", text);
  if (!std::isfinite(value)) return fmt::format("must be a finite number, got {}", text);
  return "";
}

}  // namespace

void CheckNumericOptions(CLI::App* app) {
  for (CLI::Option* option : app->get_options()) {
    const std::string type = option->get_type_name();
    const std::string base = type.substr(0, type.find(':'));
    if (base == "INT" || base == "UINT") {
      const bool is_signed = base == "INT";
      // A transform (check() would not keep the rewritten text), run before the option's other checks.
      option->transform(CLI::Validator([is_signed](std::string& text) { return CheckInteger(text, is_signed); }, ""));
    } else if (base == "FLOAT") {
      option->check(CLI::Validator([](std::string& text) { return CheckFinite(text); }, ""));
    }
  }
  for (CLI::App* command : app->get_subcommands([](CLI::App*) { return true; })) CheckNumericOptions(command);
}

void RefuseSharedPaths(const std::vector<std::string>& inputs, const std::vector<OutputPath>& outputs) {
  CheckOutputs(inputs, outputs);
}

}  // namespace cheval::cli

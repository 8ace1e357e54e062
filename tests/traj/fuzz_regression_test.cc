// Replays the inputs of tests/data/fuzz/<target>/ (crashes and interesting inputs found by the
// libFuzzer targets of fuzz/, docs/fuzzing.md) exactly as the fuzz target does, and asserts what
// the target asserts: the input either parses and the trajectory has the target's properties, or it
// throws a cheval::InputError (UsageError for --columns) whose message begins with the path.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "cheval/traj/stamp.h"
#include "../support/test_data.h"

namespace cheval::traj {
namespace {

namespace fs = std::filesystem;

// The fuzz targets (fuzz/CMakeLists.txt), one folder of inputs each.
const char* const kTargets[] = {"tum", "tumv", "euroc", "kitti", "vins", "csv", "auto", "column_map", "stamp"};

// The csv target's first byte picks one of these (kCsvColumnMaps in fuzz/trajectory_fuzzer.cc).
constexpr std::array<const char*, 6> kCsvColumnMaps{{
    "t,px,py,pz,qx,qy,qz,qw",
    "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz",
    "t,px,py,pz,roll,pitch,yaw",
    "t_ms,_,px,py,pz",
    "t_us,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz",
    "t_ns,_,_,px,py,pz,skip",
}};

struct FuzzInput {
  std::string target;
  std::string file;  // path of the input
};

// gtest prints the parameter of a failing case; the file says it all.
void PrintTo(const FuzzInput& input, std::ostream* os) { *os << input.file; }

std::vector<FuzzInput> ListInputs() {
  std::vector<FuzzInput> inputs;
  for (const char* target : kTargets) {
    const fs::path folder = fs::path(cheval::testing::FixturePath("fuzz")) / target;
    if (!fs::is_directory(folder)) continue;
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.is_regular_file()) files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
    for (const std::string& file : files) inputs.push_back({target, file});
  }
  return inputs;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << "cannot open " << path;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool AllFinite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

void ExpectRoundTrip(const Trajectory& trajectory, Format format) {
  SCOPED_TRACE(std::string("written as ") + std::string(ToString(format)));
  const std::string text = FormatTrajectory(trajectory.View(), format);
  ReadOptions options;
  options.format = format;
  Trajectory again;
  try {
    again = ParseTrajectory(text, "roundtrip", options);
    EXPECT_EQ(DetectFormat("roundtrip", text), format);
  } catch (const Error& e) {
    FAIL() << "the written text does not read back: " << e.what() << "\n" << text;
  }
  ASSERT_EQ(again.size(), trajectory.size());
  EXPECT_TRUE(std::equal(again.stamps_ns().begin(), again.stamps_ns().end(), trajectory.stamps_ns().begin()));
  EXPECT_TRUE(SameBits(again.raw_positions(), trajectory.raw_positions()));
  if (trajectory.channels().orientation == OrientationKind::kQuaternion) {
    EXPECT_TRUE(SameBits(again.raw_orientations(), trajectory.raw_orientations()));
  }
  if (trajectory.channels().velocity) {
    EXPECT_TRUE(SameBits(again.raw_velocities(), trajectory.raw_velocities()));
  }
}

// The properties CheckTrajectory() of fuzz/trajectory_fuzzer.cc traps on.
void ExpectProperties(const Trajectory& t, Format format, const ColumnMap* columns) {
  const Eigen::Index n = t.size();
  const Channels& c = t.channels();
  ASSERT_GE(n, 1);
  ASSERT_EQ(static_cast<Eigen::Index>(t.stamps_ns().size()), n);
  ASSERT_EQ(static_cast<Eigen::Index>(t.raw_positions().size()), 3 * n);
  ASSERT_EQ(static_cast<Eigen::Index>(t.raw_orientations().size()), OrientationStride(c.orientation) * n);
  ASSERT_EQ(static_cast<Eigen::Index>(t.raw_velocities().size()), c.velocity ? 3 * n : 0);
  ASSERT_EQ(static_cast<Eigen::Index>(t.raw_angular_velocities().size()), c.angular_velocity ? 3 * n : 0);
  EXPECT_TRUE(AllFinite(t.raw_positions()));
  EXPECT_TRUE(AllFinite(t.raw_orientations()));
  EXPECT_TRUE(AllFinite(t.raw_velocities()));
  EXPECT_TRUE(AllFinite(t.raw_angular_velocities()));
  switch (format) {
    case Format::kTum:
    case Format::kTumV:
      EXPECT_EQ(c, (Channels{OrientationKind::kQuaternion, format == Format::kTumV, false, true}));
      break;
    case Format::kEuroc:
    case Format::kVins:
      EXPECT_TRUE(c.orientation == OrientationKind::kQuaternion && !c.angular_velocity && c.has_stamps);
      break;
    case Format::kKitti:
      EXPECT_EQ(c, (Channels{OrientationKind::kMatrix, false, false, false}));
      for (Eigen::Index i = 0; i < n; ++i) EXPECT_EQ(t.stamps_ns()[i], i * kNanosecondsPerSecond);
      break;
    case Format::kCsv: {
      const auto has = [&](ColumnRole role) {
        return std::find(columns->roles.begin(), columns->roles.end(), role) != columns->roles.end();
      };
      const OrientationKind kind =
          has(ColumnRole::kQx) || has(ColumnRole::kRoll) ? OrientationKind::kQuaternion : OrientationKind::kNone;
      EXPECT_EQ(c, (Channels{kind, has(ColumnRole::kVx), has(ColumnRole::kWx), true}));
      break;
    }
    case Format::kAuto: ADD_FAILURE() << "format_read is kAuto"; break;
  }
  if (c.orientation == OrientationKind::kNone) return;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = t.Rotation(i);
    const double orthonormality = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (c.orientation == OrientationKind::kQuaternion) {
      const double* q = t.raw_orientations().data() + 4 * i;
      Eigen::Vector4d u(q[0], q[1], q[2], q[3]);
      u /= u.cwiseAbs().maxCoeff();
      u.normalize();
      const Eigen::Matrix3d expected = Eigen::Quaterniond(u[3], u[0], u[1], u[2]).toRotationMatrix();
      EXPECT_LE(orthonormality, 1e-9) << "pose " << i;
      EXPECT_NEAR(R.determinant(), 1.0, 1e-9) << "pose " << i;
      EXPECT_LE((R - expected).cwiseAbs().maxCoeff(), 1e-9) << "pose " << i;
    } else {
      EXPECT_LE(orthonormality, 0.1) << "pose " << i;
      EXPECT_NEAR(R.determinant(), 1.0, 0.1) << "pose " << i;
    }
  }
  ExpectRoundTrip(t, c.velocity ? Format::kTumV : Format::kTum);
  ExpectRoundTrip(t, Format::kEuroc);
}

void ExpectColumnMapRules(const ColumnMap& map) {
  std::array<int, 23> count{};
  for (ColumnRole r : map.roles) ++count[static_cast<size_t>(r)];
  auto n = [&](ColumnRole r) { return count[static_cast<size_t>(r)]; };
  ASSERT_FALSE(map.roles.empty());
  EXPECT_NE(map.roles.back(), ColumnRole::kSkip);
  for (size_t r = 1; r < count.size(); ++r) EXPECT_LE(count[r], 1) << "role " << r;
  EXPECT_EQ(n(ColumnRole::kTimeSeconds) + n(ColumnRole::kTimeMilliseconds) + n(ColumnRole::kTimeMicroseconds) +
                n(ColumnRole::kTimeNanoseconds),
            1);
  EXPECT_EQ(n(ColumnRole::kPx) + n(ColumnRole::kPy) + n(ColumnRole::kPz), 3);
  const int q = n(ColumnRole::kQx) + n(ColumnRole::kQy) + n(ColumnRole::kQz) + n(ColumnRole::kQw);
  const int e = n(ColumnRole::kRoll) + n(ColumnRole::kPitch) + n(ColumnRole::kYaw);
  EXPECT_TRUE((q == 0 || q == 4) && (e == 0 || e == 3) && (q == 0 || e == 0));
  EXPECT_EQ(ColumnMap::Parse(map.ToString()).roles, map.roles);
}

// The stamp target: byte 0 holds require_integer (bit 0) and the scale (bit 1: byte 1 as a signed
// char, else 9, 6, 3, 0 by bits 2-3).
void ReplayStamp(std::string_view input) {
  if (input.size() < 2) return;
  const auto b0 = static_cast<uint8_t>(input[0]);
  const bool require_integer = (b0 & 1) != 0;
  int scale = 0;
  size_t begin = 1;
  if ((b0 & 2) != 0) {
    scale = static_cast<int8_t>(input[1]);
    begin = 2;
  } else {
    constexpr int kScales[4] = {9, 6, 3, 0};
    scale = kScales[(b0 >> 2) & 3];
  }
  const std::string text(input.substr(begin));
  SCOPED_TRACE("text '" + text + "', scale " + std::to_string(scale));
  const StampParseResult r = ParseDecimalStamp(text, scale, require_integer);
  if (!r.error && scale == 9) {
    const StampParseResult again = ParseDecimalStamp(FormatSeconds(r.value), 9, true);
    ASSERT_FALSE(again.error);
    EXPECT_EQ(again.value, r.value);
  }
  if (r.error && *r.error == StampParseError::kNotAnInteger) {
    EXPECT_TRUE(require_integer);
  }
  const bool plain = !text.empty() && text.find_first_not_of("0123456789.eE+-") == std::string::npos;
  if (!plain) {
    EXPECT_TRUE(r.error && *r.error == StampParseError::kNotANumber);
    return;
  }
  char* end = nullptr;
  const long double parsed = std::strtold(text.c_str(), &end);
  const bool complete = end == text.c_str() + text.size();
  const long double reference = parsed * std::pow(10.0L, static_cast<long double>(scale));
  if (!r.error) {
    EXPECT_TRUE(complete);
    EXPECT_LE(std::fabs(static_cast<long double>(r.value) - reference), 2.0L + std::fabs(reference) * 1e-17L);
  } else if (*r.error == StampParseError::kNotANumber) {
    EXPECT_FALSE(complete);
  } else if (*r.error == StampParseError::kOutOfRange) {
    EXPECT_TRUE(complete);
    EXPECT_FALSE(std::fabs(reference) < 9223372036854775807.0L * (1.0L - 1e-17L));
  }
}

// The trajectory targets and column_map, as LLVMFuzzerTestOneInput of fuzz/trajectory_fuzzer.cc.
void ReplayTrajectory(const std::string& target, std::string_view content) {
  ReadOptions options;
  if (target == "column_map") {
    const size_t newline = content.find('\n');
    const std::string_view spec = content.substr(0, newline);
    content = newline == std::string_view::npos ? std::string_view() : content.substr(newline + 1);
    try {
      options.columns = ColumnMap::Parse(spec);
    } catch (const UsageError& e) {
      EXPECT_EQ(std::string_view(e.what()).substr(0, 10), "--columns:") << e.what();
      return;
    }
    ExpectColumnMapRules(*options.columns);
    options.format = Format::kCsv;
  } else if (target == "csv") {
    if (content.empty()) return;
    options.columns = ColumnMap::Parse(kCsvColumnMaps[static_cast<uint8_t>(content[0]) % kCsvColumnMaps.size()]);
    options.format = Format::kCsv;
    content.remove_prefix(1);
  } else {
    options.format = target == "auto" ? Format::kAuto : *FormatFromString(target);
  }
  const std::string path = options.format == Format::kTum || options.format == Format::kTumV ||
                                   options.format == Format::kKitti
                               ? "fuzz.txt"
                               : "fuzz.csv";
  std::optional<Format> detected;
  if (options.format == Format::kAuto) {
    try {
      detected = DetectFormat(path, content);
    } catch (const InputError& e) {
      EXPECT_EQ(std::string_view(e.what()).substr(0, path.size() + 1), path + ":") << e.what();
    }
  }
  Format format_read = Format::kAuto;
  try {
    const Trajectory trajectory = ParseTrajectory(content, path, options, &format_read);
    if (options.format == Format::kAuto) {
      ASSERT_TRUE(detected.has_value());
      EXPECT_EQ(format_read, *detected);
    } else {
      EXPECT_EQ(format_read, options.format);
    }
    ExpectProperties(trajectory, format_read, options.columns ? &*options.columns : nullptr);
  } catch (const InputError& e) {
    EXPECT_EQ(std::string_view(e.what()).substr(0, path.size() + 1), path + ":") << e.what();
    if (options.format == Format::kAuto && !detected) {
      EXPECT_EQ(format_read, Format::kAuto);
    }
  }
  // Any other exception (UsageError here, ComputeError from the writer, std::logic_error, ...)
  // escapes and fails the test, as it crashes the fuzz target.
}

class FuzzRegressionTest : public ::testing::TestWithParam<FuzzInput> {};

TEST_P(FuzzRegressionTest, ParsesWithPropertiesOrThrowsInputError) {
  const FuzzInput& input = GetParam();
  const std::string bytes = ReadBytes(input.file);
  if (input.target == "stamp") {
    ReplayStamp(bytes);
  } else {
    ReplayTrajectory(input.target, bytes);
  }
}

std::string TestName(const ::testing::TestParamInfo<FuzzInput>& info) {
  std::string name = info.param.target + "_" + fs::path(info.param.file).filename().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Inputs, FuzzRegressionTest, ::testing::ValuesIn(ListInputs()), TestName);

// An empty or missing folder would make the suite above pass vacuously.
TEST(FuzzRegression, EveryTargetHasInputs) {
  for (const char* target : kTargets) {
    const fs::path folder = fs::path(cheval::testing::FixturePath("fuzz")) / target;
    ASSERT_TRUE(fs::is_directory(folder)) << folder;
    EXPECT_FALSE(fs::is_empty(folder)) << folder;
  }
}

// The crashes the fuzzers found, with the message the fix gives them.
TEST(FuzzRegression, FoundCrashesThrowTheExactMessage) {
  struct Found {
    const char* target;
    const char* file;
    const char* message;
  };
  const Found kFound[] = {
      // A shear with determinant 1 passed the determinant check; its quaternion came out as zero.
      {"kitti", "shear_with_determinant_one",
       "fuzz.txt:2:1: error: expected a rotation matrix in fields 1-3, 5-7, 9-11 (r00..r22), got one that is not "
       "orthonormal (max |R*R^T - I| = inf)"},
      // qx = 1e175: q·q overflowed and the rotation silently became the identity.
      {"vins", "quaternion_norm_overflow",
       "fuzz.csv:1:32: error: quaternion (qw qx qy qz) is too large: its squared norm overflows a double; expected a "
       "rotation"},
  };
  for (const Found& found : kFound) {
    const std::string content = ReadBytes(cheval::testing::FixturePath(std::string("fuzz/") + found.target + "/" +
                                                                       found.file));
    ReadOptions options;
    options.format = *FormatFromString(found.target);
    try {
      ParseTrajectory(content, found.target == std::string("kitti") ? "fuzz.txt" : "fuzz.csv", options);
      ADD_FAILURE() << "no error for " << found.file;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), found.message);
    }
  }
}

}  // namespace
}  // namespace cheval::traj

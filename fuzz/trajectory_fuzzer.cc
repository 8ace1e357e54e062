// libFuzzer target for the trajectory readers. One source, built once per reader: CHEVAL_FUZZ_FORMAT
// names the format given to ParseTrajectory (tum, tumv, euroc, kitti, vins, csv, auto), or
// column_map for ColumnMap::Parse.
//
// The input is the file's content. For csv the first byte picks one of kCsvColumnMaps and the rest
// is the content; for column_map the first line is a --columns spec (checked against the rules of
// ColumnMap::Parse and ToString()) and the rest is read as csv with it. A documented failure (a cheval::Error) is fine; anything else is a bug: a crash, a
// sanitizer report, a hang, another exception escaping (libFuzzer aborts on those), or a parsed
// trajectory that breaks one of the properties below (__builtin_trap()):
//   - sizes agree across channels and there is at least one pose;
//   - positions, orientations and velocities are finite;
//   - the channels are those the format promises;
//   - every rotation is a rotation (orthonormal, det +1; for quaternions the one of q/|q|);
//   - with an orientation, FormatTrajectory(kTum, or kTumV with velocity) parsed again gives the
//     same stamps and bit-identical positions (and quaternions / velocities when stored as read),
//     and DetectFormat recognises the written text; the same for kEuroc.
//
// tests/traj/fuzz_regression_test.cc replays the inputs of tests/data/fuzz/<target>/ the same way.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "cheval/traj/stamp.h"

#ifndef CHEVAL_FUZZ_FORMAT
#error "define CHEVAL_FUZZ_FORMAT (tum, tumv, euroc, kitti, vins, csv, auto or column_map)"
#endif
#define CHEVAL_FUZZ_STRINGIFY2(x) #x
#define CHEVAL_FUZZ_STRINGIFY(x) CHEVAL_FUZZ_STRINGIFY2(x)

namespace cheval::traj {
namespace {

// Keep in sync with kCsvColumnMaps in tests/traj/fuzz_regression_test.cc.
constexpr std::array<const char*, 6> kCsvColumnMaps{{
    "t,px,py,pz,qx,qy,qz,qw",                          // TUM as csv (either separator)
    "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz",              // EuRoC/VINS with velocity
    "t,px,py,pz,roll,pitch,yaw",                       // Euler angles (iCub)
    "t_ms,_,px,py,pz",                                 // position only, a skipped column
    "t_us,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz",     // everything (crazyflie/DIDO)
    "t_ns,_,_,px,py,pz,skip",                          // position only, trailing skip
}};

#define FUZZ_CHECK(condition)                                                                \
  do {                                                                                       \
    if (!(condition)) {                                                                      \
      std::fprintf(stderr, "property violated: %s (%s:%d)\n", #condition, __FILE__, __LINE__); \
      __builtin_trap();                                                                      \
    }                                                                                        \
  } while (0)

bool AllFinite(const std::vector<double>& values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// max |R·Rᵀ − I| and det R.
void RotationError(const Eigen::Matrix3d& R, double* orthonormality, double* det) {
  *orthonormality = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  *det = R.determinant();
}

// Writes `trajectory` in `format` and reads it back; the result must match what was written.
void CheckRoundTrip(const Trajectory& trajectory, Format format) {
  const std::string text = FormatTrajectory(trajectory.View(), format);
  const std::string path = "roundtrip";
  Trajectory again;
  Format detected = Format::kAuto;
  try {
    ReadOptions options;
    options.format = format;
    again = ParseTrajectory(text, path, options);
    detected = DetectFormat(path, text);
  } catch (const Error& e) {
    std::fprintf(stderr, "written text does not read back: %s\n--- text ---\n%s\n", e.what(), text.c_str());
    __builtin_trap();
  }
  FUZZ_CHECK(detected == format);
  FUZZ_CHECK(again.size() == trajectory.size());
  FUZZ_CHECK(std::equal(again.stamps_ns().begin(), again.stamps_ns().end(), trajectory.stamps_ns().begin()));
  FUZZ_CHECK(SameBits(again.raw_positions(), trajectory.raw_positions()));
  if (trajectory.channels().orientation == OrientationKind::kQuaternion) {
    FUZZ_CHECK(SameBits(again.raw_orientations(), trajectory.raw_orientations()));
  }
  if (trajectory.channels().velocity) {
    FUZZ_CHECK(again.channels().velocity);
    FUZZ_CHECK(SameBits(again.raw_velocities(), trajectory.raw_velocities()));
  }
}

void CheckTrajectory(const Trajectory& t, Format format, const ColumnMap* columns) {
  const Eigen::Index n = t.size();
  const Channels& c = t.channels();
  FUZZ_CHECK(n >= 1);
  FUZZ_CHECK(static_cast<Eigen::Index>(t.stamps_ns().size()) == n);
  FUZZ_CHECK(static_cast<Eigen::Index>(t.raw_positions().size()) == 3 * n);
  FUZZ_CHECK(static_cast<Eigen::Index>(t.raw_orientations().size()) == OrientationStride(c.orientation) * n);
  FUZZ_CHECK(static_cast<Eigen::Index>(t.raw_velocities().size()) == (c.velocity ? 3 * n : 0));
  FUZZ_CHECK(static_cast<Eigen::Index>(t.raw_angular_velocities().size()) == (c.angular_velocity ? 3 * n : 0));
  FUZZ_CHECK(AllFinite(t.raw_positions()));
  FUZZ_CHECK(AllFinite(t.raw_orientations()));
  FUZZ_CHECK(AllFinite(t.raw_velocities()));
  FUZZ_CHECK(AllFinite(t.raw_angular_velocities()));

  switch (format) {
    case Format::kTum:
    case Format::kTumV:
      FUZZ_CHECK(c == (Channels{OrientationKind::kQuaternion, format == Format::kTumV, false, true}));
      break;
    case Format::kEuroc:
    case Format::kVins:
      FUZZ_CHECK(c.orientation == OrientationKind::kQuaternion && !c.angular_velocity && c.has_stamps);
      break;
    case Format::kKitti:
      FUZZ_CHECK(c == (Channels{OrientationKind::kMatrix, false, false, false}));
      for (Eigen::Index i = 0; i < n; ++i) FUZZ_CHECK(t.stamps_ns()[i] == i * kNanosecondsPerSecond);
      break;
    case Format::kCsv: {
      bool quaternion = false, euler = false, velocity = false, angular = false;
      for (ColumnRole r : columns->roles) {
        quaternion = quaternion || r == ColumnRole::kQx;
        euler = euler || r == ColumnRole::kRoll;
        velocity = velocity || r == ColumnRole::kVx;
        angular = angular || r == ColumnRole::kWx;
      }
      const OrientationKind kind = quaternion || euler ? OrientationKind::kQuaternion : OrientationKind::kNone;
      FUZZ_CHECK(c == (Channels{kind, velocity, angular, true}));
      break;
    }
    case Format::kAuto: FUZZ_CHECK(false); break;
  }

  if (c.orientation == OrientationKind::kNone) return;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = t.Rotation(i);
    double orthonormality = 0, det = 0;
    RotationError(R, &orthonormality, &det);
    if (c.orientation == OrientationKind::kQuaternion) {
      // The rotation of q/|q|, computed without overflow or underflow: scale by the largest |q_i| first.
      const double* q = t.raw_orientations().data() + 4 * i;
      Eigen::Vector4d u(q[0], q[1], q[2], q[3]);
      u /= u.cwiseAbs().maxCoeff();
      u.normalize();
      const Eigen::Matrix3d expected = Eigen::Quaterniond(u[3], u[0], u[1], u[2]).toRotationMatrix();
      FUZZ_CHECK(orthonormality <= 1e-9 && std::abs(det - 1.0) <= 1e-9);
      FUZZ_CHECK((R - expected).cwiseAbs().maxCoeff() <= 1e-9);
    } else {
      // KITTI matrices are stored as read; they must be rotations up to the reader's tolerance.
      FUZZ_CHECK(orthonormality <= 0.1 && std::abs(det - 1.0) <= 0.1);
    }
  }
  CheckRoundTrip(t, c.velocity ? Format::kTumV : Format::kTum);
  CheckRoundTrip(t, Format::kEuroc);
}

// The message of a documented failure starts with the file's path.
void CheckMessage(const Error& e, const std::string& path) {
  FUZZ_CHECK(std::string_view(e.what()).substr(0, path.size() + 1) == path + ":");
}

}  // namespace
}  // namespace cheval::traj

namespace cheval::traj {
namespace {

// A parsed column map satisfies the rules ColumnMap::Parse documents, and its spec parses back to it.
void CheckColumnMap(const ColumnMap& map) {
  std::array<int, 23> count{};
  for (ColumnRole r : map.roles) ++count[static_cast<size_t>(r)];
  auto n = [&](ColumnRole r) { return count[static_cast<size_t>(r)]; };
  FUZZ_CHECK(!map.roles.empty() && map.roles.back() != ColumnRole::kSkip);
  for (size_t r = 1; r < count.size(); ++r) FUZZ_CHECK(count[r] <= 1);
  FUZZ_CHECK(n(ColumnRole::kTimeSeconds) + n(ColumnRole::kTimeMilliseconds) + n(ColumnRole::kTimeMicroseconds) +
                 n(ColumnRole::kTimeNanoseconds) == 1);
  FUZZ_CHECK(n(ColumnRole::kPx) + n(ColumnRole::kPy) + n(ColumnRole::kPz) == 3);
  const int q = n(ColumnRole::kQx) + n(ColumnRole::kQy) + n(ColumnRole::kQz) + n(ColumnRole::kQw);
  const int e = n(ColumnRole::kRoll) + n(ColumnRole::kPitch) + n(ColumnRole::kYaw);
  const int v = n(ColumnRole::kVx) + n(ColumnRole::kVy) + n(ColumnRole::kVz);
  const int w = n(ColumnRole::kWx) + n(ColumnRole::kWy) + n(ColumnRole::kWz);
  FUZZ_CHECK((q == 0 || q == 4) && (e == 0 || e == 3) && (q == 0 || e == 0) && (v == 0 || v == 3) &&
             (w == 0 || w == 3));
  const std::string spec = map.ToString();
  try {
    FUZZ_CHECK(ColumnMap::Parse(spec).roles == map.roles);
  } catch (const Error& error) {
    std::fprintf(stderr, "ToString() '%s' does not parse back: %s\n", spec.c_str(), error.what());
    __builtin_trap();
  }
}

}  // namespace
}  // namespace cheval::traj

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace cheval::traj;
  const std::string_view target = CHEVAL_FUZZ_STRINGIFY(CHEVAL_FUZZ_FORMAT);
  std::string_view content(reinterpret_cast<const char*>(data), size);
  ReadOptions options;
  if (target == "column_map") {
    // The first line is a --columns spec, the rest a csv file read with it.
    const size_t newline = content.find('\n');
    const std::string_view spec = content.substr(0, newline);
    content = newline == std::string_view::npos ? std::string_view() : content.substr(newline + 1);
    try {
      options.columns = ColumnMap::Parse(spec);
    } catch (const cheval::UsageError& e) {
      FUZZ_CHECK(std::string_view(e.what()).substr(0, 10) == "--columns:");
      return 0;
    }
    CheckColumnMap(*options.columns);
    options.format = Format::kCsv;
  } else if (target == "csv") {
    if (content.empty()) return 0;
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

  // Auto-detection on its own: it either names a format or throws.
  std::optional<Format> detected;
  if (options.format == Format::kAuto) {
    try {
      detected = DetectFormat(path, content);
      FUZZ_CHECK(*detected != Format::kAuto && *detected != Format::kCsv);
    } catch (const cheval::Error& e) {
      CheckMessage(e, path);
    }
  }

  Format format_read = Format::kAuto;
  try {
    const Trajectory trajectory = ParseTrajectory(content, path, options, &format_read);
    FUZZ_CHECK(format_read != Format::kAuto);
    if (options.format == Format::kAuto) {
      FUZZ_CHECK(detected.has_value() && format_read == *detected);
    } else {
      FUZZ_CHECK(format_read == options.format);
    }
    CheckTrajectory(trajectory, format_read, options.columns ? &*options.columns : nullptr);
  } catch (const cheval::Error& e) {
    CheckMessage(e, path);
    // Detection failing must make the read fail: kAuto never silently picks a format.
    FUZZ_CHECK(options.format != Format::kAuto || detected.has_value() || format_read == Format::kAuto);
  }
  return 0;
}

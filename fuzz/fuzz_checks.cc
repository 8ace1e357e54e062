// The properties of the fuzz targets (fuzz_checks.h). Each check returns the first property it finds
// violated, so a fuzz target can print it and trap, and the regression test can print it and fail.
#include "fuzz_checks.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "cheval/cheb/curve.h"
#include "cheval/cheb/model.h"
#include "cheval/common/error.h"
#include "cheval/traj/io.h"
#include "cheval/traj/stamp.h"

namespace cheval::fuzz {
namespace {

using traj::ColumnMap;
using traj::ColumnRole;
using traj::Format;
using traj::OrientationKind;
using traj::StampParseError;
using traj::StampParseResult;
using traj::Trajectory;

// nullopt, or what is wrong.
using Violation = std::optional<std::string>;

Violation Describe(const char* condition, int line, const std::string& where = {}) {
  std::string out = std::string(condition) + " (fuzz_checks.cc:" + std::to_string(line) + ")";
  if (!where.empty()) out += ", " + where;
  return out;
}

// Returns the violation from the enclosing function (which returns Violation) when `condition` does
// not hold; an optional second argument (a std::string) says where, e.g. the pose. Parenthesise a
// condition with braces in it: a comma inside {} would split the macro's arguments.
#define FUZZ_REQUIRE(condition, ...) \
  do {                               \
    if (!(condition)) return Describe(#condition, __LINE__ __VA_OPT__(, ) __VA_ARGS__); \
  } while (0)

// Returns the violation of a nested check, if any.
#define FUZZ_PROPAGATE(check)                         \
  do {                                                \
    if (Violation nested = (check)) return nested;    \
  } while (0)

// Input bytes as text a terminal can show: printable ASCII as is, everything else as \xNN.
std::string Printable(std::string_view bytes) {
  std::string out;
  for (const char c : bytes) {
    const auto u = static_cast<unsigned char>(c);
    if (u == '\n') {
      out += "\\n";
    } else if (u >= 0x20 && u < 0x7f && u != '\\') {
      out += c;
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", u);
      out += escaped;
    }
  }
  return out;
}

bool AllFinite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

// Bit for bit: a round trip must not move a value by even one ulp (and -0.0 stays -0.0).
bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

bool StartsWith(std::string_view text, std::string_view prefix) { return text.substr(0, prefix.size()) == prefix; }

// A message quotes the input's bytes escaped and cut (traj::QuoteField): no control byte reaches the
// terminal, and no field makes it long, whatever the input.
Violation CheckMessageQuoting(std::string_view message, const char* call) {
  const bool control = std::any_of(message.begin(), message.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u < 0x20 || u == 0x7f;
  });
  if (control) return std::string(call) + " threw a message with a raw control byte: " + Printable(message);
  if (message.size() > 1000) return std::string(call) + " threw a message of " + std::to_string(message.size()) + " bytes";
  return std::nullopt;
}

// A documented failure of the reader: an InputError whose message starts with the file's path.
Violation CheckInputError(const Error& e, const std::string& path, const char* call) {
  if (dynamic_cast<const InputError*>(&e) == nullptr) {
    return std::string(call) + " threw a cheval::Error that is not an InputError: " + e.what();
  }
  if (!StartsWith(e.what(), path + ":")) {
    return std::string(call) + " threw an InputError whose message does not begin with '" + path + ":': " + e.what();
  }
  return CheckMessageQuoting(e.what(), call);
}

// Writes `trajectory` in `format` and reads it back with that format; the result must match what was
// written, and DetectFormat must recognise the text.
Violation CheckRoundTrip(const Trajectory& trajectory, Format format) {
  const std::string where = "written as " + std::string(traj::ToString(format));
  const std::string path = "roundtrip";
  std::string text;
  Trajectory again;
  Format detected = Format::kAuto;
  try {
    text = traj::FormatTrajectory(trajectory.View(), format);
  } catch (const Error& e) {
    return where + ": FormatTrajectory threw: " + e.what();
  }
  try {
    traj::ReadOptions options;
    options.format = format;
    again = traj::ParseTrajectory(text, path, options);
    detected = traj::DetectFormat(path, text);
  } catch (const Error& e) {
    return where + ": the written text does not read back: " + e.what() + "\n--- text ---\n" + text;
  }
  FUZZ_REQUIRE(detected == format, where);
  FUZZ_REQUIRE(again.size() == trajectory.size(), where);
  FUZZ_REQUIRE(std::equal(again.stamps_ns().begin(), again.stamps_ns().end(), trajectory.stamps_ns().begin()),
               where);
  FUZZ_REQUIRE(SameBits(again.raw_positions(), trajectory.raw_positions()), where);
  if (trajectory.channels().orientation == OrientationKind::kQuaternion) {
    FUZZ_REQUIRE(SameBits(again.raw_orientations(), trajectory.raw_orientations()), where);
  }
  if (trajectory.channels().velocity) {
    FUZZ_REQUIRE(again.channels().velocity, where);
    FUZZ_REQUIRE(SameBits(again.raw_velocities(), trajectory.raw_velocities()), where);
  }
  return std::nullopt;
}

// The properties of a trajectory read as `format` (with `columns` for kCsv).
Violation CheckTrajectory(const Trajectory& t, Format format, const ColumnMap* columns) {
  using traj::Channels;
  const Eigen::Index n = t.size();
  const Channels& c = t.channels();
  FUZZ_REQUIRE(n >= 1);
  FUZZ_REQUIRE(static_cast<Eigen::Index>(t.stamps_ns().size()) == n);
  FUZZ_REQUIRE(static_cast<Eigen::Index>(t.raw_positions().size()) == 3 * n);
  FUZZ_REQUIRE(static_cast<Eigen::Index>(t.raw_orientations().size()) == traj::OrientationStride(c.orientation) * n);
  FUZZ_REQUIRE(static_cast<Eigen::Index>(t.raw_velocities().size()) == (c.velocity ? 3 * n : 0));
  FUZZ_REQUIRE(static_cast<Eigen::Index>(t.raw_angular_velocities().size()) == (c.angular_velocity ? 3 * n : 0));
  FUZZ_REQUIRE(AllFinite(t.raw_positions()));
  FUZZ_REQUIRE(AllFinite(t.raw_orientations()));
  FUZZ_REQUIRE(AllFinite(t.raw_velocities()));
  FUZZ_REQUIRE(AllFinite(t.raw_angular_velocities()));
  // Every difference of two stamps fits int64 nanoseconds (the readers refuse a wider span).
  if (n > 0) {
    const auto [lowest, highest] = std::minmax_element(t.stamps_ns().begin(), t.stamps_ns().end());
    int64_t span = 0;
    FUZZ_REQUIRE(!__builtin_sub_overflow(*highest, *lowest, &span));
  }

  switch (format) {
    case Format::kTum:
    case Format::kTumV:
      // tumv: 11 fields, or 14 with the body angular velocity (what `cheval velocity --angular` writes).
      FUZZ_REQUIRE(c == (Channels{OrientationKind::kQuaternion, format == Format::kTumV,
                                  format == Format::kTumV && c.angular_velocity, true}));
      break;
    case Format::kEuroc:
    case Format::kVins:
      FUZZ_REQUIRE(c.orientation == OrientationKind::kQuaternion && !c.angular_velocity && c.has_stamps);
      break;
    case Format::kKitti:
      FUZZ_REQUIRE(c == (Channels{OrientationKind::kMatrix, false, false, false}));
      for (Eigen::Index i = 0; i < n; ++i) {
        FUZZ_REQUIRE(t.stamps_ns()[i] == i * traj::kNanosecondsPerSecond, "pose " + std::to_string(i));
      }
      break;
    case Format::kCsv: {
      FUZZ_REQUIRE(columns != nullptr);
      const auto has = [&](ColumnRole role) {
        return std::find(columns->roles.begin(), columns->roles.end(), role) != columns->roles.end();
      };
      const OrientationKind kind =
          has(ColumnRole::kQx) || has(ColumnRole::kRoll) ? OrientationKind::kQuaternion : OrientationKind::kNone;
      FUZZ_REQUIRE(c == (Channels{kind, has(ColumnRole::kVx), has(ColumnRole::kWx), true}));
      break;
    }
    case Format::kAuto: FUZZ_REQUIRE(format != Format::kAuto); break;
  }

  if (c.orientation == OrientationKind::kNone) return std::nullopt;
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::string pose = "pose " + std::to_string(i);
    const Eigen::Matrix3d R = t.Rotation(i);
    const double orthonormality = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    const double det = R.determinant();
    if (c.orientation == OrientationKind::kQuaternion) {
      // The rotation of q/|q|, computed without overflow or underflow: scale by the largest |q_i| first.
      const double* q = t.raw_orientations().data() + 4 * i;
      Eigen::Vector4d u(q[0], q[1], q[2], q[3]);
      u /= u.cwiseAbs().maxCoeff();
      u.normalize();
      const Eigen::Matrix3d expected = Eigen::Quaterniond(u[3], u[0], u[1], u[2]).toRotationMatrix();
      FUZZ_REQUIRE(orthonormality <= 1e-9 && std::abs(det - 1.0) <= 1e-9, pose);
      FUZZ_REQUIRE((R - expected).cwiseAbs().maxCoeff() <= 1e-9, pose);
    } else {
      // KITTI matrices are stored as read; they must be rotations up to the reader's tolerance.
      FUZZ_REQUIRE(orthonormality <= 0.1 && std::abs(det - 1.0) <= 0.1, pose);
    }
  }
  FUZZ_PROPAGATE(CheckRoundTrip(t, c.velocity ? Format::kTumV : Format::kTum));
  FUZZ_PROPAGATE(CheckRoundTrip(t, Format::kEuroc));
  return std::nullopt;
}

// A parsed column map satisfies the rules ColumnMap::Parse documents, and its spec parses back to it.
Violation CheckColumnMap(const ColumnMap& map) {
  std::array<int, 23> count{};
  for (ColumnRole r : map.roles) ++count[static_cast<size_t>(r)];
  auto n = [&](ColumnRole r) { return count[static_cast<size_t>(r)]; };
  FUZZ_REQUIRE(!map.roles.empty() && map.roles.back() != ColumnRole::kSkip);
  for (size_t r = 1; r < count.size(); ++r) FUZZ_REQUIRE(count[r] <= 1, "role " + std::to_string(r));
  FUZZ_REQUIRE(n(ColumnRole::kTimeSeconds) + n(ColumnRole::kTimeMilliseconds) + n(ColumnRole::kTimeMicroseconds) +
                   n(ColumnRole::kTimeNanoseconds) ==
               1);
  FUZZ_REQUIRE(n(ColumnRole::kPx) + n(ColumnRole::kPy) + n(ColumnRole::kPz) == 3);
  const int q = n(ColumnRole::kQx) + n(ColumnRole::kQy) + n(ColumnRole::kQz) + n(ColumnRole::kQw);
  const int e = n(ColumnRole::kRoll) + n(ColumnRole::kPitch) + n(ColumnRole::kYaw);
  const int v = n(ColumnRole::kVx) + n(ColumnRole::kVy) + n(ColumnRole::kVz);
  const int w = n(ColumnRole::kWx) + n(ColumnRole::kWy) + n(ColumnRole::kWz);
  FUZZ_REQUIRE((q == 0 || q == 4) && (e == 0 || e == 3) && (q == 0 || e == 0) && (v == 0 || v == 3) &&
               (w == 0 || w == 3));
  const std::string spec = map.ToString();
  try {
    FUZZ_REQUIRE(ColumnMap::Parse(spec).roles == map.roles, "spec '" + spec + "'");
  } catch (const Error& error) {
    return "ToString() '" + spec + "' does not parse back: " + error.what();
  }
  return std::nullopt;
}

Violation CheckTrajectoryTarget(std::string_view target, std::string_view content) {
  traj::ReadOptions options;
  if (target == "column_map") {
    // The first line is a column map spec, the rest a csv file read with it.
    const size_t newline = content.find('\n');
    const std::string_view spec = content.substr(0, newline);
    content = newline == std::string_view::npos ? std::string_view() : content.substr(newline + 1);
    try {
      options.columns = ColumnMap::Parse(spec);
    } catch (const UsageError& e) {
      FUZZ_REQUIRE(StartsWith(e.what(), "ReadOptions::columns:"), std::string("message: ") + e.what());
      return CheckMessageQuoting(e.what(), "ColumnMap::Parse");
    } catch (const Error& e) {
      return std::string("ColumnMap::Parse threw a cheval::Error that is not a UsageError: ") + e.what();
    }
    FUZZ_PROPAGATE(CheckColumnMap(*options.columns));
    options.format = Format::kCsv;
  } else if (target == "csv") {
    if (content.empty()) return std::nullopt;
    options.columns = ColumnMap::Parse(kCsvColumnMaps[static_cast<uint8_t>(content[0]) % kCsvColumnMaps.size()]);
    options.format = Format::kCsv;
    content.remove_prefix(1);
  } else if (target == "auto") {
    options.format = Format::kAuto;
  } else {
    const std::optional<Format> format = traj::FormatFromString(target);
    if (!format || *format == Format::kAuto || *format == Format::kCsv) {
      throw std::invalid_argument("unknown fuzz target '" + std::string(target) + "'");
    }
    options.format = *format;
  }
  const std::string path = options.format == Format::kTum || options.format == Format::kTumV ||
                                   options.format == Format::kKitti
                               ? "fuzz.txt"
                               : "fuzz.csv";

  // Auto-detection on its own: it either names a format it can read without a column map or throws.
  std::optional<Format> detected;
  if (options.format == Format::kAuto) {
    try {
      detected = traj::DetectFormat(path, content);
      FUZZ_REQUIRE(*detected != Format::kAuto && *detected != Format::kCsv);
    } catch (const Error& e) {
      FUZZ_PROPAGATE(CheckInputError(e, path, "DetectFormat"));
    }
  }

  Format format_read = Format::kAuto;
  std::optional<Trajectory> trajectory;
  try {
    trajectory = traj::ParseTrajectory(content, path, options, &format_read);
  } catch (const Error& e) {
    FUZZ_PROPAGATE(CheckInputError(e, path, "ParseTrajectory"));
    // Detection failing must make the read fail there: kAuto never silently picks a format.
    FUZZ_REQUIRE(options.format != Format::kAuto || detected.has_value() || format_read == Format::kAuto);
    return std::nullopt;
  }
  FUZZ_REQUIRE(format_read != Format::kAuto);
  if (options.format == Format::kAuto) {
    FUZZ_REQUIRE(detected.has_value() && format_read == *detected);
  } else {
    FUZZ_REQUIRE(format_read == options.format);
  }
  return CheckTrajectory(*trajectory, format_read, options.columns ? &*options.columns : nullptr);
}

// Plain decimal text: a sign, digits, dots and exponents only (no spaces, hex, inf or nan, all of
// which strtold accepts and ParseDecimalStamp rejects by design).
bool IsPlainDecimal(std::string_view text) {
  return !text.empty() && text.find_first_not_of("0123456789.eE+-") == std::string_view::npos;
}

Violation CheckStamp(const std::string& text, int scale, bool require_integer) {
  const StampParseResult r = traj::ParseDecimalStamp(text, scale, require_integer);

  if (!r.error && scale == 9) {
    const std::string printed = traj::FormatSeconds(r.value);
    const StampParseResult again = traj::ParseDecimalStamp(printed, 9);
    FUZZ_REQUIRE(!again.error && again.value == r.value, "printed '" + printed + "'");
    const StampParseResult again_integer = traj::ParseDecimalStamp(printed, 9, true);
    FUZZ_REQUIRE(!again_integer.error && again_integer.value == r.value, "printed '" + printed + "'");
  }
  if (r.error && *r.error == StampParseError::kNotAnInteger) FUZZ_REQUIRE(require_integer);

  // Differential check against long double (only for text strtold must read the same way).
  if (!IsPlainDecimal(text)) {
    FUZZ_REQUIRE(r.error && *r.error == StampParseError::kNotANumber);
    return std::nullopt;
  }
  char* end = nullptr;
  const long double parsed = std::strtold(text.c_str(), &end);
  const bool complete = end == text.c_str() + text.size();
  // long double carries a 64-bit mantissa, so the exact int64 result is within a few units of it.
  const long double reference = parsed * std::pow(10.0L, static_cast<long double>(scale));
  if (!r.error) {
    const std::string value = "value " + std::to_string(r.value);
    FUZZ_REQUIRE(complete, value);
    FUZZ_REQUIRE(std::isfinite(reference), value);
    FUZZ_REQUIRE(std::fabs(static_cast<long double>(r.value) - reference) <= 2.0L + std::fabs(reference) * 1e-17L,
                 value);
    return std::nullopt;
  }
  switch (*r.error) {
    case StampParseError::kNotANumber: FUZZ_REQUIRE(!complete); break;
    case StampParseError::kOutOfRange:
      FUZZ_REQUIRE(complete);
      // INT64_MAX + 0.5 rounds out of range; allow the long double error of the reference.
      FUZZ_REQUIRE(!(std::fabs(reference) < 9223372036854775807.0L * (1.0L - 1e-17L)));
      break;
    case StampParseError::kNotAnInteger: FUZZ_REQUIRE(complete); break;
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> CheckTrajectoryInput(std::string_view target, std::string_view data) {
  Violation violation = CheckTrajectoryTarget(target, data);
  if (violation) *violation += "\n--- input (" + std::string(target) + ") ---\n" + Printable(data);
  return violation;
}

std::optional<std::string> CheckStampInput(std::string_view data) {
  if (data.size() < 2) return std::nullopt;
  const auto options = static_cast<uint8_t>(data[0]);
  const bool require_integer = (options & 1) != 0;
  int scale = 0;
  size_t begin = 1;
  if ((options & 2) != 0) {
    scale = static_cast<int8_t>(data[1]);
    begin = 2;
  } else {
    constexpr int kScales[4] = {9, 6, 3, 0};  // seconds, ms, us, ns: as the readers call it
    scale = kScales[(options >> 2) & 3];
  }
  const std::string text(data.substr(begin));
  Violation violation = CheckStamp(text, scale, require_integer);
  if (violation) {
    *violation += "; text '" + Printable(text) + "', scale " + std::to_string(scale) +
                  (require_integer ? ", require_integer" : "");
  }
  return violation;
}

std::optional<std::string> CheckModelInput(std::string_view data) {
  const std::string path = "fuzz.json";
  cheb::TrajectoryModel model;
  try {
    model = cheb::ParseModelJson(data, path);
  } catch (const InputError& e) {
    if (std::string_view(e.what()).substr(0, path.size() + 1) != path + ":") {
      return Describe("the InputError begins with the path", __LINE__, e.what());
    }
    return std::nullopt;
  }
  const std::string text = cheb::WriteModelJson(model);
  std::string again;
  try {
    again = cheb::WriteModelJson(cheb::ParseModelJson(text, path));
  } catch (const InputError& e) {
    return Describe("a written model reads back", __LINE__, e.what());
  }
  if (again != text) return Describe("write -> read -> write gives the same text", __LINE__);
  // CurveFromModel throws std::invalid_argument for an inconsistent model: that escapes as a bug.
  const cheb::Curve curve = cheb::CurveFromModel(model);
  bool moderate = true;  // every number small enough that its polynomials cannot overflow
  for (const cheb::ModelSegment& segment : model.segments) {
    for (const cheb::ModelWindow& window : segment.windows) {
      for (double end : {window.core_begin, window.core_end, window.fit_begin, window.fit_end}) {
        moderate = moderate && std::abs(end) < 1e100;
      }
      for (const Eigen::VectorXd& values : window.values) moderate = moderate && values.cwiseAbs().maxCoeff() < 1e100;
    }
  }
  Eigen::VectorXd value(model.dimension);
  for (const cheb::ModelSegment& segment : model.segments) {
    const int64_t middle = segment.first_ns + (segment.last_ns - segment.first_ns) / 2;
    for (const int64_t stamp : {segment.first_ns, middle, segment.last_ns}) {
      try {
        curve.EvaluateValue(stamp, value);
      } catch (const ComputeError& e) {
        return Describe("the curve evaluates inside its segments", __LINE__,
                        "stamp " + std::to_string(stamp) + ": " + e.what());
      }
      if (moderate && !value.allFinite()) {
        return Describe("finite values from moderate numbers", __LINE__, "stamp " + std::to_string(stamp));
      }
    }
  }
  return std::nullopt;
}

namespace {

struct CurveSamples {
  std::vector<int64_t> stamps;
  Eigen::MatrixXd values;
};

CurveSamples DecodeCurveSamples(std::string_view data) {
  CurveSamples out;
  const int d = 1 + static_cast<unsigned char>(data[0]) % 3;
  const size_t record = 1 + static_cast<size_t>(d), count = (data.size() - 1) / record;
  out.values.resize(static_cast<Eigen::Index>(count), d);
  int64_t stamp = 1'403'636'580'000'000'000;  // EuRoC-like absolute stamps
  for (size_t i = 0; i < count; ++i) {
    const auto* r = reinterpret_cast<const unsigned char*>(data.data() + 1 + i * record);
    const int code = r[0];
    stamp += code <= 250 ? int64_t{code} * 50'000 : int64_t{code - 250} * 100'000'000;
    out.stamps.push_back(stamp);
    const double t = static_cast<double>(stamp - out.stamps.front()) * 1e-9;
    for (int c = 0; c < d; ++c) {
      const double motion = 0.3 * t * (c == 0) + 0.02 * std::sin(2 * std::numbers::pi * 2.3 * t + c) + 0.004 * std::cos(9.0 * t);
      out.values(static_cast<Eigen::Index>(i), c) = motion + 1e-4 * static_cast<signed char>(r[1 + c]);
    }
  }
  return out;
}

// The properties of one fitted curve (CheckCurveInput).
Violation CheckFittedCurve(const cheb::Curve& curve, const CurveSamples& samples, const char* which) {
  const std::string name(which);
  for (const cheb::CurveSegment& segment : curve.segments()) {
    const auto& windows = segment.windows;
    FUZZ_REQUIRE(!windows.empty(), name);
    FUZZ_REQUIRE(windows.front().core_begin == segment.begin && windows.back().core_end == segment.end, name);
    for (size_t k = 0; k < windows.size(); ++k) {
      FUZZ_REQUIRE(windows[k].core_begin < windows[k].core_end, name + " window " + std::to_string(k));
      FUZZ_REQUIRE(windows[k].fit_begin <= windows[k].core_begin && windows[k].fit_end >= windows[k].core_end,
                   name + " window " + std::to_string(k));
      if (k > 0) FUZZ_REQUIRE(windows[k].core_begin == windows[k - 1].core_end, name + " window " + std::to_string(k));
    }
  }
  // Curve::FromParts throws std::invalid_argument for parts that do not tile: that escapes as a bug.
  cheb::Curve::FromParts(curve.origin_ns(), curve.segments(), curve.noise_sigma(), curve.residual_rms());
  Eigen::MatrixXd p, v, a;
  curve.EvaluateMany(samples.stamps, 2, &p, &v, &a);
  FUZZ_REQUIRE(p.allFinite() && v.allFinite() && a.allFinite(), name);
  return std::nullopt;
}

}  // namespace

std::optional<std::string> CheckCurveInput(std::string_view data) {
  if (data.size() < 2) return std::nullopt;
  const CurveSamples samples = DecodeCurveSamples(data);
  std::optional<cheb::Curve> with, without;
  std::string with_error, without_error;
  cheb::CurveOptions options;
  try {
    with = cheb::FitCurve(samples.stamps, samples.values, options);
  } catch (const ComputeError& e) {
    with_error = e.what();
  }
  options.end_caps = false;
  try {
    without = cheb::FitCurve(samples.stamps, samples.values, options);
  } catch (const ComputeError& e) {
    without_error = e.what();
  }
  FUZZ_REQUIRE(with.has_value() == without.has_value(), "with caps: '" + with_error + "', without: '" + without_error + "'");
  if (!with) return std::nullopt;
  FUZZ_PROPAGATE(CheckFittedCurve(*with, samples, "with end caps"));
  FUZZ_PROPAGATE(CheckFittedCurve(*without, samples, "without end caps"));
  return std::nullopt;
}

int TrapOnViolation(const std::optional<std::string>& violation) {
  if (violation) {
    std::fprintf(stderr, "property violated: %s\n", violation->c_str());
    __builtin_trap();
  }
  return 0;
}

}  // namespace cheval::fuzz
